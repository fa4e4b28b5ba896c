"""Objects that own C++ state refuse to be copied.

``copy.copy`` of a Python wrapper copies its ``__dict__``, so the copy and the original would
share one C++ object (a SlipControl, Observer, plant): stepping the copy would change the
original's next outputs, and two grippers' samples would interleave. The bindings expose no
copy of that state, so these wrappers refuse ``copy.copy``, ``copy.deepcopy`` and pickling
with a TypeError that says what to do instead: build a new object from the same arguments.
"""

from __future__ import annotations

__all__ = ["NoCopy"]


class NoCopy:
    """Mixin: ``copy.copy``, ``copy.deepcopy`` and ``pickle`` raise TypeError."""

    __slots__ = ()

    def _refuse_copy(self, what: str):
        name = type(self).__name__
        raise TypeError(
            f"{name} cannot be {what}: it owns C++ state (filters, integrators, timers) that a "
            f"copy would share with the original; create a new {name} with the same arguments")

    def __copy__(self):
        self._refuse_copy("copied (copy.copy)")

    def __deepcopy__(self, memo):
        self._refuse_copy("copied (copy.deepcopy)")

    def __reduce_ex__(self, protocol):
        self._refuse_copy("pickled")
