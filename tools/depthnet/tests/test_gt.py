
import cv2
import numpy as np
import pytest

import seven_scenes_gt as gt


def matrix_from_xyzw(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


@pytest.mark.parametrize("rvec", [(0.1, -0.2, 0.3), (np.pi, 0, 0), (0, 3.1, 0.2), (0, 0, -3.0),
                                  (1.5, 1.5, -1.0), (0, 0, 0)])
def test_quaternion_round_trip(rvec):
    r, _ = cv2.Rodrigues(np.array(rvec, np.float64))
    q = gt.quaternion_xyzw(r)
    assert np.linalg.norm(q) == pytest.approx(1.0) and q[3] >= 0
    assert np.allclose(matrix_from_xyzw(q), r, atol=1e-9)


def test_writes_tum_with_index_over_30(tmp_path):
    for i in range(3):
        m = np.eye(4)
        m[:3, 3] = [i, 2 * i, 3.5]
        np.savetxt(tmp_path / f"frame-{i:06d}.pose.txt", m)
    out = str(tmp_path / "gt.tum")
    assert gt.main([str(tmp_path), "--frames", "1:3", "--out", out]) == 0
    rows = [l.split() for l in open(out) if not l.startswith("#")]
    assert [float(r[0]) for r in rows] == pytest.approx([1 / 30, 2 / 30])
    assert [float(v) for v in rows[1][1:]] == pytest.approx([2, 4, 3.5, 0, 0, 0, 1])
    assert gt.main([str(tmp_path), "--frames", "0:9", "--out", out]) == 2
