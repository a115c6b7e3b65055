"""imscal.read_robot_log against the text of the file, imscal.calibrate against `imscal
calibrate` on the shipped campaign, and their errors against the command line."""
import json

import numpy as np
import pytest

import imscal


def test_read_robot_log_matches_the_csv_text(repo):
    path = repo / "datasets" / "campaign" / "robot.csv"
    log = imscal.read_robot_log(str(path), robot="kr16")
    # Independent reading: numpy's parser of the same text (rad columns), every row.
    text = np.loadtxt(path, delimiter=",", comments="#", skiprows=4)
    assert log["robot"] == "kr16"
    assert log["cycle_s"] == 0.002
    assert log["joint_names"] == ["A1", "A2", "A3", "A4", "A5", "A6"]
    np.testing.assert_array_equal(log["t_s"], text[:, 0])
    np.testing.assert_array_equal(log["payload_kg"], text[:, 1])
    np.testing.assert_array_equal(log["q_desired_rad"], text[:, 2:8])
    np.testing.assert_array_equal(log["q_internal_rad"], text[:, 8:14])


def test_a_bad_value_names_file_line_and_field(repo, tmp_path):
    lines = (repo / "datasets" / "campaign" / "robot.csv").read_text().splitlines()[:50]
    fields = lines[9].split(",")
    fields[3] = "abc"  # q_desired_A2_rad on file line 10
    lines[9] = ",".join(fields)
    bad = tmp_path / "robot.csv"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(imscal.InputError) as caught:
        imscal.read_robot_log(str(bad))
    error = caught.value
    assert isinstance(error, ValueError)
    assert (error.file, error.line, error.field) == (str(bad), 10, "q_desired_A2_rad")
    assert error.problem in str(error)


def test_a_log_of_another_robot_is_refused(repo):
    with pytest.raises(imscal.InputError, match="ur10"):
        imscal.read_robot_log(str(repo / "datasets" / "campaign" / "robot.csv"), robot="ur10")


@pytest.fixture(scope="module")
def campaign_calibration(repo, cli, tmp_path_factory):
    """The shipped campaign's calibration by the command line (5 s) and by Python."""
    out = tmp_path_factory.mktemp("calibrate") / "cli"
    campaign = repo / "datasets" / "campaign"
    done = cli("calibrate", "--imu", campaign / "imu.csv", "--robot-log", campaign / "robot.csv",
               "--config", campaign / "calibrate.yaml", "--out", out)
    python = imscal.calibrate(str(campaign / "imu.csv"), str(campaign / "robot.csv"),
                              config=str(campaign / "calibrate.yaml"))
    return out, done, python


def assert_same_json(actual, expected, tolerance=1e-12, path=""):
    """Equal structure and text; numbers equal to `tolerance`, relative or absolute."""
    assert type(actual) is type(expected), path
    if isinstance(expected, dict):
        assert actual.keys() == expected.keys(), path
        for key in expected:
            assert_same_json(actual[key], expected[key], tolerance, f"{path}/{key}")
    elif isinstance(expected, list):
        assert len(actual) == len(expected), path
        for i, (a, e) in enumerate(zip(actual, expected)):
            assert_same_json(a, e, tolerance, f"{path}[{i}]")
    elif isinstance(expected, float):
        assert actual == pytest.approx(expected, rel=tolerance, abs=tolerance), path
    else:
        assert actual == expected, path


def test_calibrate_matches_the_command_line(campaign_calibration):
    out, done, python = campaign_calibration
    # The same session on the same files: frames.json and mounting_report.json alike, summary.txt
    # equal; the verdict and its reasons as printed. The covariances (sigmas, correlations)
    # come from SuiteSparse's QR on ATLAS BLAS, whose kernels sum in an order that follows the
    # buffers' alignment in memory: two calls in one Python process already differ in the last
    # bits (measured against the command line: 6.4e-14 at most, in frames.json's correlations,
    # some of which are ~1e-16 themselves). 1e-12, relative or absolute, is far below any
    # printed figure.
    assert_same_json(python["frames"], json.loads((out / "frames.json").read_text()))
    assert_same_json(python["mounting_report"],
                     json.loads((out / "mounting_report.json").read_text()))
    assert python["summary"] == (out / "summary.txt").read_text()
    printed = [line for line in done.stdout.splitlines() if not line.startswith("[")]  # no log
    assert printed[0] == f"verdict: {python['verdict']}"
    assert printed[1:] == [f"  - {reason}" for reason in python["reasons"]]


def test_calibrate_gives_the_joint_errors_the_file_holds(campaign_calibration):
    out, _, python = campaign_calibration
    written = imscal.read_joint_errors(str(out / "joint_errors.csv"))
    # joint_errors.csv holds 17 significant digits: the same doubles.
    for key in ["t_s", "payload_kg", "q_desired_rad", "q_measured_rad", "q_internal_rad"]:
        np.testing.assert_array_equal(python["joint_errors"][key], written[key], err_msg=key)


def test_calibrate_names_file_line_and_field_of_bad_input(repo, tmp_path):
    campaign = repo / "datasets" / "campaign"
    config = tmp_path / "calibrate.yaml"
    text = (campaign / "calibrate.yaml").read_text() + "joint_errors: maybe\n"
    # The relative paths of the shipped config are relative to its folder: name them absolute.
    text = text.replace("../sensors/", f"{repo}/datasets/sensors/").replace(
        "../robots/", f"{repo}/datasets/robots/").replace(
        "unit_calibration: unit-calibration.yaml",
        f"unit_calibration: {campaign}/unit-calibration.yaml")
    config.write_text(text)
    with pytest.raises(imscal.InputError) as caught:
        imscal.calibrate(str(campaign / "imu.csv"), str(campaign / "robot.csv"),
                         config=str(config))
    lines = text.splitlines()
    assert (caught.value.file, caught.value.line, caught.value.field) == (
        str(config), len(lines), "joint_errors")
