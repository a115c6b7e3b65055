"""imscal.evaluate_paths against `imscal evaluate` and against a closed form."""
import json

import numpy as np
import pytest

import imscal


def write_path(file, t_s, p_m):
    with open(file, "w") as out:
        out.write("t_s,x_m,y_m,z_m,qw,qx,qy,qz\n")
        for t, p in zip(t_s, p_m):
            out.write(f"{t!r},{p[0]!r},{p[1]!r},{p[2]!r},1,0,0,0\n")


@pytest.fixture
def line_paths(tmp_path):
    """A 0.5 m line at 0.25 m/s along x, and three cycles offset 1 mm along y (+0.1 mm in z
    in the last two): every attained point lies 1 mm (or sqrt(1 + 0.01) mm) beside the line."""
    t = np.arange(0.0, 2.0 + 1e-9, 0.004)
    line = np.stack([0.25 * t, np.zeros_like(t), np.full_like(t, 0.8)], axis=1)
    commanded = tmp_path / "commanded.csv"
    write_path(commanded, t, line)
    attained = []
    for k, dz in enumerate([0.0, 1e-4, 1e-4]):
        f = tmp_path / f"cycle{k}.csv"
        write_path(f, t, line + [0.0, 1e-3, dz])
        attained.append(f)
    return commanded, attained


def test_evaluate_paths_matches_the_command_line(cli, tmp_path, line_paths):
    commanded, attained = line_paths
    figures = tmp_path / "figures.json"
    cli("evaluate", "--commanded", commanded, "--attained", *attained, "--out", figures)
    expected = json.loads(figures.read_text())
    got = imscal.evaluate_paths(str(commanded), [str(a) for a in attained])
    # Same code, and figures.json holds the shortest decimal of each double: equal.
    for key, value in expected.items():
        if key in ("commanded", "per_cycle"):
            continue
        if value is None:  # a figure that needs more cycles: null in JSON, NaN here
            assert np.isnan(got[key]), key
        else:
            assert got[key] == value, key
    assert [c["max_path_deviation_mm"] for c in got["per_cycle"]] == [
        c["max_path_deviation_mm"] for c in expected["per_cycle"]]


def test_evaluate_paths_gives_the_offset_of_a_parallel_path(line_paths):
    commanded, attained = line_paths
    got = imscal.evaluate_paths(str(commanded), [str(attained[0])])
    # One cycle 1 mm beside the line: AT_p and the path deviation are 1 mm (to rounding of the
    # decimal coordinates, 1e-9 mm); RT_p needs two cycles.
    assert got["AT_p_mm"] == pytest.approx(1.0, abs=1e-9)
    assert got["max_path_deviation_mm"] == pytest.approx(1.0, abs=1e-9)
    assert got["commanded_speed_m_s"] == pytest.approx(0.25, rel=1e-12)


def test_read_path_refuses_a_quaternion_that_is_not_unit(tmp_path):
    bad = tmp_path / "path.csv"
    bad.write_text("t_s,x_m,y_m,z_m,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.1,0,0,0,2,0,0,0\n")
    with pytest.raises(imscal.InputError) as caught:
        imscal.read_path(str(bad))
    assert (caught.value.line, caught.value.field) == (3, "qw")
