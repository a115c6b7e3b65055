"""imscal.read_imu and imscal.mechanize against the text of the files and `imscal mechanize`."""
import numpy as np
import pytest

import imscal


def test_read_imu_matches_the_csv_text(repo):
    path = repo / "datasets" / "campaign" / "imu.csv"
    imu = imscal.read_imu(str(path))
    # Independent reading: numpy's own parser of the same text, every row.
    text = np.loadtxt(path, delimiter=",", comments="#", skiprows=11)
    assert imu["quantity"] == "increments"
    assert imu["nominal_dt_s"] == 0.001
    assert imu["site"] == pytest.approx((48.78232, 9.18162, 245.4), abs=0)
    assert imu["gyro"].shape == (text.shape[0], 3)
    # Both parse the same decimal text to the nearest double: equal bit for bit.
    np.testing.assert_array_equal(imu["t_s"], text[:, 0])
    np.testing.assert_array_equal(imu["gyro"], text[:, 1:4])
    np.testing.assert_array_equal(imu["acc"], text[:, 4:7])


def test_mechanize_matches_the_command_line(repo, cli, tmp_path):
    imu = repo / "datasets" / "default" / "imu.imsb"
    done = cli("mechanize", "--input", imu, "--align-s", "1.9", "--heading-deg", "0", "--out",
               tmp_path)
    nav = imscal.mechanize(str(imu), align_s=1.9, heading_deg=0.0)
    # trajectory.csv: t_s,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s in the shortest decimal
    # that reads back to the same double, from the same code: equal bit for bit.
    csv = np.loadtxt(tmp_path / "trajectory.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(nav["t_s"], csv[:, 0])
    np.testing.assert_array_equal(nav["p_W_m"], csv[:, 1:4])
    np.testing.assert_array_equal(nav["q_W_S_wxyz"], csv[:, 4:8])
    np.testing.assert_array_equal(nav["v_W_m_s"], csv[:, 8:11])
    assert nav["attitude_source"] in done.stdout


def test_mechanize_refuses_a_missing_site_like_the_command_line(repo, cli, tmp_path):
    # The campaign's header without its site lines.
    lines = (repo / "datasets" / "campaign" / "imu.csv").read_text().splitlines()[:400]
    bad = tmp_path / "imu.csv"
    bad.write_text("\n".join(l for l in lines if not l.startswith("# site_")) + "\n")
    with pytest.raises(imscal.InputError) as caught:
        imscal.mechanize(str(bad), align_s=0.2)
    assert caught.value.file == str(bad)
    assert caught.value.field == "site"
    done = cli("mechanize", "--input", bad, "--align-s", "0.2", "--out", tmp_path / "nav",
               expect=2)
    assert str(caught.value) in done.stdout + done.stderr  # spdlog writes to stdout
