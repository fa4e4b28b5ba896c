"""The sensor-frame transform shared by the log readers and the ROS node
(lugrip.io.contact_wrench), and SlipControl.step's shape check. No ROS needed."""

from __future__ import annotations

import numpy as np
import pytest

import lugrip
from lugrip.io import contact_wrench
from lugrip.io._ros import to_contact


def test_contact_wrench_flip_and_offset_against_a_hand_computed_wrench():
    """Independent reference: a point contact at (x, y) on the pad surface z = -d below a
    sensor origin, force F and pure torsion t_z at the contact; the sensor measures
    M = r x F + (0, 0, t_z). The transform must return (F_z, F_x, F_y, t_z); flipped sensors
    (z toward the object) read the rotated wrench and must give the same row."""
    d, x, y = 0.012, 0.003, -0.002
    F = np.array([0.4, -0.7, 6.0])
    tz = 2.5e-3
    r = np.array([x, y, -d])
    M = np.cross(r, F) + [0.0, 0.0, tz]
    row = contact_wrench(F, M, contact_offset=d, floor=0.01)
    np.testing.assert_allclose(row, [F[2], F[0], F[1], tz], rtol=0, atol=1e-12)
    R = np.diag([1.0, -1.0, -1.0])  # the sensor's frame rotated by pi about x
    np.testing.assert_allclose(contact_wrench(R @ F, R @ M, flip_normal=True,
                                              contact_offset=d, floor=0.01),
                               row, atol=1e-12)
    # no offset: the moment's z is taken as it is
    np.testing.assert_allclose(contact_wrench(F, M), [F[2], F[0], F[1], M[2]])


def test_batch_and_row_agree_with_the_log_readers_rule():
    """A batch uses the log readers' floor (5 % of the median pressing force); rows above it
    get the same tau one by one with that floor."""
    rng = np.random.default_rng(3)
    f = np.c_[rng.normal(0, 0.5, (50, 2)), rng.uniform(0.0, 8.0, 50)]
    m = rng.normal(0, 1e-3, (50, 3))
    batch = contact_wrench(f, m, contact_offset=0.01)
    tau, _ = to_contact(f, m, 0.01)
    np.testing.assert_array_equal(batch[:, 3], tau)
    floor = max(1e-3, 0.05 * float(np.median(f[:, 2][f[:, 2] > 0])))
    rows = np.array([contact_wrench(f[i], m[i], contact_offset=0.01, floor=floor)
                     for i in range(50)])
    np.testing.assert_allclose(rows, batch, rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="shape"):
        contact_wrench(np.zeros(2), np.zeros(3))


@pytest.mark.parametrize("shape", [(4, 2), (8,), (2, 4, 1), (1, 4), (3, 4)])
def test_step_refuses_any_shape_but_fingers_by_4(shape):
    """A transposed (4, 2) or flat (8,) array was read row by row; now every shape but
    (fingers, 4) is refused with a ValueError naming the shape. No plant."""
    sc = lugrip.SlipControl(lugrip.ContactParams.table1())
    with pytest.raises(ValueError, match=r"per finger, a \(2, 4\) array"):
        sc.step(np.ones(shape))
    assert sc.step(np.tile([5.0, 0.1, 0.0, 1e-4], (2, 1))).force > 0
    one = lugrip.SlipControl(lugrip.ContactParams.table1(), fingers=1)
    assert one.step([5.0, 0.1, 0.0, 1e-4]).force > 0
    with pytest.raises(ValueError, match=r"a \(1, 4\) array, or \(4,\)"):
        one.step(np.ones((4, 2)))
