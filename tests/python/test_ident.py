"""imscal.read_joint_errors, imscal.identify and imscal.Precontrol against `imscal identify` and
`imscal compensate` on the same generated files, and the identified model against its truth."""
import json

import numpy as np
import pytest

import imscal

CYCLE_S = 0.002
SAMPLES = 15000  # 30 s: every joint's visited speed cells hold more than min_rows (2000)
POLE = 0.9       # q_measured(k) = POLE q_measured(k-1) + (1 - POLE) q_desired(k-1)


def joint_motion():
    """Six joints swinging at different frequencies, each following its command through the
    first-order lag above (a unit-gain model the identification must find), with 1 urad noise."""
    t = np.arange(SAMPLES) * CYCLE_S
    q_d = np.stack([0.3 * np.sin(2 * np.pi * (0.3 + 0.1 * j) * t) + 0.1 * j for j in range(6)],
                   axis=1)
    q_m = np.empty_like(q_d)
    q_m[0] = q_d[0]
    for k in range(1, SAMPLES):
        q_m[k] = POLE * q_m[k - 1] + (1 - POLE) * q_d[k - 1]
    q_m += np.random.default_rng(1).normal(0.0, 1e-6, q_m.shape)
    return t, q_d, q_m


def write_csv(file, header, columns, t, blocks):
    with open(file, "w") as out:
        out.write(header + ",".join(["t_s", "payload_kg"] + columns) + "\n")
        for k in range(len(t)):
            values = [repr(t[k]), "5"] + [repr(v) for b in blocks for v in b[k]]
            out.write(",".join(values) + "\n")


@pytest.fixture(scope="module")
def files(tmp_path_factory, repo):
    folder = tmp_path_factory.mktemp("ident")
    t, q_d, q_m = joint_motion()
    names = [f"A{j}" for j in range(1, 7)]
    col = lambda kind: [f"q_{kind}_{n}_rad" for n in names]
    write_csv(folder / "joint_errors.csv",
              "# imscal-joint-errors: 1\n# robot: kr16\n# cycle_s: 0.002\n",
              col("desired") + col("measured") + col("internal"), t, [q_d, q_m, q_m])
    write_csv(folder / "robot.csv", "# imscal-robot-log: 1\n# robot: kr16\n# cycle_s: 0.002\n",
              col("desired") + col("internal"), t, [q_d, q_m])
    # The shipped paper-form config with a sweep for a first-order joint and no backlash term.
    config = (repo / "datasets" / "identification" / "ident-paper.yaml").read_text()
    for old, new in [("na: [1, 32]", "na: [1, 2]"), ("nb: [1, 32]", "nb: [1, 2]"),
                     ("dead_time: [0, 4]", "dead_time: [0, 2]"),
                     ("backlash:\n  enabled: true", "backlash:\n  enabled: false")]:
        assert old in config
        config = config.replace(old, new)
    (folder / "ident.yaml").write_text(config)
    return folder, q_d, q_m


def test_read_joint_errors_gives_the_written_angles(files):
    folder, q_d, q_m = files
    log = imscal.read_joint_errors(str(folder / "joint_errors.csv"))
    # repr() writes the shortest decimal that reads back to the same double.
    np.testing.assert_array_equal(log["q_desired_rad"], q_d)
    np.testing.assert_array_equal(log["q_measured_rad"], q_m)
    assert log["segments"] == [(0, SAMPLES)]


@pytest.fixture(scope="module")
def identified(files, cli):
    folder, _, _ = files
    cli("identify", "--joint-errors", folder / "joint_errors.csv", "--config",
        folder / "ident.yaml", "--out", folder / "cli")
    return imscal.identify(str(folder / "joint_errors.csv"), str(folder / "ident.yaml"))


def test_identify_matches_the_command_line(files, identified):
    folder, _, _ = files
    expected = json.loads((folder / "cli" / "parameters.json").read_text())
    # Same code on the same file: the same table, every coefficient of every cell.
    assert identified["table"] == expected
    assert identified["failures"] == [""] * 6


def test_identify_finds_the_lag(identified):
    # The held-out joint-error fit of a noise-free first-order lag with 1 urad noise on a
    # joint error of ~mrad: above 95 % (the noise is ~0.1 % of the error's amplitude).
    assert min(identified["joint_error_fit_percent"]) > 95.0


def offsets_columns(file):
    """The columns of an offsets.csv of `imscal compensate` by name, as text."""
    rows = [l for l in file.read_text().splitlines() if not l.startswith("#")]
    return {name: column for name, column in zip(rows[0].split(","),
                                                 zip(*(r.split(",") for r in rows[1:])))}


def assert_steps_as_written(offsets, states, expected):
    """Offsets (N, 6) and states equal to those of an offsets.csv: it holds the shortest decimal
    of each double, so equal."""
    offsets = np.array(offsets)
    for j in range(6):
        np.testing.assert_array_equal(offsets[:, j],
                                      np.array(expected[f"offset_A{j + 1}_rad"], dtype=float))
    assert states == list(expected["state"])
    return offsets


def test_precontrol_steps_as_the_command_line(files, identified, cli):
    folder, q_d, _ = files
    cli("compensate", "--table", folder / "cli" / "parameters.json", "--robot-log",
        folder / "robot.csv", "--out", folder / "offsets.csv")
    expected = offsets_columns(folder / "offsets.csv")
    precontrol = imscal.Precontrol(str(folder / "cli" / "parameters.json"))
    assert precontrol.preview_cycles == 0  # the paper's forward form
    offsets, states = [], []
    for k in range(SAMPLES):
        # The cycle number from the time stamp, as `imscal compensate` counts it.
        offset, state, _ = precontrol.step(q_d[k], 5.0, round(k * CYCLE_S / CYCLE_S))
        offsets.append(offset)
        states.append(state)
    offsets = assert_steps_as_written(offsets, states, expected)
    # The precontrol's offset is the model's joint error: after the engagement (0.2 s settle,
    # 0.2 s fade-in) it follows q_d - q_m of the data to the model's fit (10 % of the peak).
    _, q_d, q_m = files
    error = q_d - q_m
    tail = slice(1000, None)
    assert np.max(np.abs(offsets[tail] - error[tail])) < 0.1 * np.max(np.abs(error))


def test_precontrol_refuses_a_table_of_another_robot(files, identified):
    folder, _, _ = files
    with pytest.raises(imscal.InputError, match="refuses"):
        imscal.Precontrol(str(folder / "cli" / "parameters.json"), robot="ur10")


def test_the_example_script_plots_the_joint_errors(files, repo, tmp_path):
    import os
    import subprocess
    import sys

    folder, q_d, q_m = files
    png = tmp_path / "joint_errors.png"
    done = subprocess.run([sys.executable, str(repo / "examples" / "python" / "plot_joint_errors.py"),
                           str(folder / "joint_errors.csv"), str(png)], capture_output=True,
                          text=True, env=os.environ)
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The printed RMS of A1 is numpy's of the generated data, in mrad to 4 decimals.
    rms_a1 = np.sqrt(np.mean(((q_d - q_m)[:, 0] * 1e3) ** 2))
    assert f"A1: RMS {rms_a1:.4f} mrad" in done.stdout


@pytest.fixture(scope="module")
def without_internal(files, cli):
    """The same joint errors without the q_internal block (a robot with one position sensor per
    joint), identified by the command line as the file with the block is."""
    folder, _, _ = files
    lines = (folder / "joint_errors.csv").read_text().splitlines()
    cut = [l if l.startswith("#") else ",".join(l.split(",")[:14]) for l in lines]
    (folder / "joint_errors_one_sensor.csv").write_text("\n".join(cut) + "\n")
    cli("identify", "--joint-errors", folder / "joint_errors_one_sensor.csv", "--config",
        folder / "ident.yaml", "--out", folder / "cli_one_sensor")
    return folder / "joint_errors_one_sensor.csv"


def test_a_file_without_the_internal_block_is_read(files, without_internal):
    folder, q_d, q_m = files
    log = imscal.read_joint_errors(str(without_internal))
    assert log["q_internal_rad"] is None
    np.testing.assert_array_equal(log["q_desired_rad"], q_d)
    np.testing.assert_array_equal(log["q_measured_rad"], q_m)


def test_identify_without_the_internal_block_gives_the_same_table(files, identified,
                                                                  without_internal):
    folder, _, _ = files
    one_sensor = json.loads((folder / "cli_one_sensor" / "parameters.json").read_text())
    with_block = json.loads((folder / "cli" / "parameters.json").read_text())
    # The identification never reads q_internal: every model equal; only the data source (file
    # name, checksum) differs.
    assert one_sensor["source"]["file"] != with_block["source"]["file"]
    assert one_sensor["source"]["samples"] == with_block["source"]["samples"]
    del one_sensor["source"], with_block["source"]
    assert one_sensor == with_block
    python = imscal.identify(str(without_internal), str(folder / "ident.yaml"))
    assert python["table"]["joints"] == identified["table"]["joints"]


@pytest.fixture(scope="module")
def torque_config(files, repo):
    """The shipped default (inverse form, model-torque input) cut to short models: na, nb <= 2,
    dead time <= 1, 4 taps of history, no transmission error."""
    folder, _, _ = files
    config = (repo / "datasets" / "identification" / "ident-default.yaml").read_text()
    for old, new in [("na: [1, 32]", "na: [1, 2]"), ("nb: [1, 32]", "nb: [1, 2]"),
                     ("dead_time: [0, 4]", "dead_time: [0, 1]"),
                     ("input_history_s: 0.12", "input_history_s: 0.008"),
                     ("preview_s: 0.04", "preview_s: 0.004"),
                     ("transmission_error: true", "transmission_error: false")]:
        assert old in config
        config = config.replace(old, new)
    (folder / "ident-torque.yaml").write_text(config)
    return folder / "ident-torque.yaml"


def without_seconds(value):
    """The value with every "seconds" key (a duration measured while running) left out."""
    if isinstance(value, dict):
        return {k: without_seconds(v) for k, v in value.items() if k != "seconds"}
    if isinstance(value, list):
        return [without_seconds(v) for v in value]
    return value


def test_identify_with_the_model_torque_matches_the_command_line(files, torque_config, repo,
                                                                 cli):
    folder, _, _ = files
    robot = repo / "datasets" / "robots" / "kr16.yaml"
    cli("identify", "--joint-errors", folder / "joint_errors.csv", "--config", torque_config,
        "--robot", robot, "--out", folder / "cli_torque")
    python = imscal.identify(str(folder / "joint_errors.csv"), str(torque_config),
                             robot=str(robot))
    # Same session on the same files: the same table and report, every number but the report's
    # timings ("seconds").
    assert python["table"] == json.loads((folder / "cli_torque" / "parameters.json").read_text())
    report = json.loads((folder / "cli_torque" / "identification_report.json").read_text())
    assert without_seconds(python["report"]) == without_seconds(report)
    assert python["table"]["extra_inputs"]


def test_identify_with_the_model_torque_needs_the_robot(files, torque_config):
    folder, _, _ = files
    with pytest.raises(imscal.InputError) as caught:
        imscal.identify(str(folder / "joint_errors.csv"), str(torque_config))
    assert (caught.value.file, caught.value.field) == (str(torque_config), "model.model_torque")


def test_precontrol_with_the_model_torque_steps_as_the_command_line(files, torque_config, repo,
                                                                    cli):
    folder, q_d, _ = files
    robot = repo / "datasets" / "robots" / "kr16.yaml"
    table = folder / "cli_torque" / "parameters.json"
    if not table.exists():
        cli("identify", "--joint-errors", folder / "joint_errors.csv", "--config", torque_config,
            "--robot", robot, "--out", folder / "cli_torque")
    cli("compensate", "--table", table, "--robot-log", folder / "robot.csv", "--robot", robot,
        "--out", folder / "offsets_torque.csv")
    expected = offsets_columns(folder / "offsets_torque.csv")
    precontrol = imscal.Precontrol(str(table))
    assert precontrol.needs_model_torque
    preview = precontrol.preview_cycles
    assert preview == 2  # 4 ms at 2 ms
    payload = np.full(SAMPLES, 5.0)
    torque = imscal.model_torques(str(robot), q_d, payload, CYCLE_S)
    offsets, states = [], []
    for k in range(SAMPLES):
        # As `imscal compensate`: the desired path and its torque preview cycles ahead (the
        # last sample held).
        ahead = min(SAMPLES - 1, k + preview)
        offset, state, _ = precontrol.step(q_d[ahead], 5.0, k, model_torque_nm=torque[ahead])
        offsets.append(offset)
        states.append(state)
    assert_steps_as_written(offsets, states, expected)
    assert "active" in states
    # Without the torques such a table deactivates (the supervisor's missing-torque event).
    bare = imscal.Precontrol(str(table))
    for k in range(5):
        bare.step(q_d[k], 5.0, k)
    assert [e["cause"] for e in bare.events()][:1] == ["model torque missing"]
