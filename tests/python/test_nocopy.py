"""Objects that own C++ state (SlipControl, GraspController, Observer, SliderModel, GraspPlant,
PatchContact)
refuse copy.copy, copy.deepcopy and pickle with a TypeError: a shallow copy of the Python
wrapper shared the C++ object, so stepping the copy changed the original's next outputs (two
grippers' samples interleaved). Two objects built from the same arguments are independent."""

from __future__ import annotations

import copy
import pickle

import lugrip
import numpy as np
import pytest
from lugrip import ContactParams, Observer, SliderModel, SlipControl


def _wrenches(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    w = np.zeros((n, 2, 4))
    w[:, :, 0] = 3.0 + rng.normal(0.0, 0.05, (n, 2))                 # f_n [N]
    w[:, :, 2] = 0.4 + 0.6 * np.linspace(0, 1, n)[:, None]            # f_y [N]
    w[:, :, 3] = 2e-3 * np.sin(np.linspace(0, 6, n))[:, None]         # tau [N m]
    return w


def _objects():
    from lugrip.sim._plant import PatchContact

    p = ContactParams.table1()
    return [SlipControl("table1"), lugrip.GraspController(p), Observer(p), SliderModel(p, 1e-4),
            PatchContact(p)]


@pytest.mark.parametrize("how", [copy.copy, copy.deepcopy, pickle.dumps],
                         ids=["copy", "deepcopy", "pickle"])
def test_stateful_objects_refuse_copies(how):
    for obj in _objects():
        with pytest.raises(TypeError, match=f"{type(obj).__name__} cannot be"):
            how(obj)


def test_grasp_plant_refuses_copies():
    from lugrip.sim._plant import GraspPlant
    from lugrip.sim.scenarios import load_scenario

    plant = GraspPlant(load_scenario("exp1_big_resin_block").plant_config())
    with pytest.raises(TypeError, match="GraspPlant cannot be copied"):
        copy.copy(plant)


def test_a_second_slip_control_does_not_change_the_first():
    """The supported way to get a second controller (a new object with the same arguments):
    stepping it between the original's steps leaves the original's outputs bit-identical to
    those of a controller stepped alone."""
    w, other = _wrenches(400, 0), _wrenches(400, 1)
    alone = SlipControl("table1")
    ref = [alone.step(w[i]).force for i in range(len(w))]
    a, b = SlipControl("table1"), SlipControl("table1")
    got = []
    for i in range(len(w)):
        got.append(a.step(w[i]).force)
        b.step(other[i])
    assert got == ref
    assert b.command != a.command or not np.array_equal(w, other)


def test_the_copy_refusal_leaves_the_original_usable():
    sc = SlipControl("table1")
    w = _wrenches(50, 2)
    with pytest.raises(TypeError):
        copy.copy(sc)
    ref = SlipControl("table1")
    assert [sc.step(x).force for x in w] == [ref.step(x).force for x in w]
    assert lugrip.SlipControl is SlipControl
