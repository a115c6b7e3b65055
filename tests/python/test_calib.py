"""imscal.read_robot_log against the text of the file, and its errors against the command line."""
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
