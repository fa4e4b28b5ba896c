"""The scene status of a plant that builds its own scene (MuJoCo, Drake): the faults a grasp
of a real scene can meet before the controller is to blame, found from each sensor sample's
contact flags and the fingers' travel (:data:`lugrip.sim.plant.SCENE_STATUS`).

A plant mixes in :class:`SceneWatch`, sets in ``reset`` ``_status`` (a fresh dict
{status: "ok", detail: "", time: None, contact_time: None}), ``_touched`` (2 bools),
``_lost`` (2 ints), ``_travel`` [m] (a finger's closing stop), ``_lift_start`` [s] and ``_T``
(the sample period [s]), defines ``_object_between()`` (the line between the pads passes
through the object, now), and calls :meth:`SceneWatch._scene_faults` after each run of samples.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LOST_SAMPLES", "SceneWatch"]

#: Consecutive contact-free sensor samples after which a pad's contact counts as lost.
LOST_SAMPLES = 10


class SceneWatch:
    """The scene-fault check shared by the engines' plants (module docstring)."""

    def _object_between(self) -> bool:  # pragma: no cover - every engine defines its own
        raise NotImplementedError

    def _scene_faults(self, t, contact, fingers) -> None:
        """Update the scene status (never raises) from the samples at times ``t`` (n,) [s],
        ``contact`` (n, 2) bool and the fingers' closing travel ``fingers`` (n, 2) [m]: a pad
        that never reached the object, a finger at its stop without contact, a contact lost
        after the grasp."""
        st = self._status
        if st["contact_time"] is None:
            both = np.flatnonzero(contact.all(axis=1))
            if both.size:
                st["contact_time"] = float(t[both[0]])
        if st["status"] != "ok" or (self._touched.all() and contact.all()):
            self._lost[:] = 0  # (the common case: both pads in contact, nothing to check)
            return
        for j in range(t.shape[0]):
            if st["status"] != "ok":
                break
            ts = float(t[j])
            self._touched |= contact[j]
            touched = self._touched
            if touched.all():
                self._lost = np.where(contact[j], 0, self._lost + 1)
                k = int(np.argmax(self._lost >= LOST_SAMPLES))
                if self._lost[k] >= LOST_SAMPLES:
                    st.update(status="lost_contact", time=ts,
                              detail=f"pad {k} without contact for {LOST_SAMPLES * self._T * 1e3:.0f} ms")
                continue
            at_stop = fingers[j] >= self._travel - 2e-4
            free = [k for k in (0, 1) if at_stop[k] and not touched[k]]
            if free:
                k = free[0]
                between = self._object_between()
                st.update(
                    status="closed_on_nothing" if between else "object_not_reached", time=ts,
                    detail=f"finger {k} closed to its stop without contact"
                    + ("" if between else "; the object is not between the fingers"),
                )
            elif ts >= self._lift_start:
                st.update(status="object_not_reached", time=ts,
                          detail=f"pad(s) {[k for k in (0, 1) if not touched[k]]} without "
                                 "contact at the lift start")
