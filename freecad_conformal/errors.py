"""One exception hierarchy for the project; messages name the object and the value at fault."""


class ConformalError(Exception):
    """Base of every error the project raises on purpose (bad input, impossible plan, ...)."""


class GeometryError(ConformalError):
    """A shape is missing, invalid, not a solid, or a geometric operation failed."""


class PlanError(ConformalError):
    """A process plan cannot be made with the given parameters."""


class BeyondTravelError(PlanError):
    """A plan laid out on the platform would leave the machine's travel: `machine` names the
    machine, `where` says which sub-part leaves it, how and where."""

    REMEDY = "Scale the part down, split it, or choose a machine with more travel"

    def __init__(self, machine: str, where: str, ways: int = 1) -> None:
        self.machine, self.where, self.ways = machine, where, ways
        tried = "" if ways == 1 else f" in any of the {ways} ways tried to build it (the first: "
        super().__init__(f"the part does not fit the travel of {machine}{tried}{where}"
                         f"{')' if tried else ''}. {self.REMEDY}")

    def __reduce__(self):
        # Crosses a child Python's pipe (jobs/coarse_child.py) whole.
        return type(self), (self.machine, self.where, self.ways)


class KinematicsError(ConformalError):
    """A pose cannot be reached by the machine, or a machine definition is invalid."""


class PostError(ConformalError):
    """A toolpath cannot be turned into G-code (unknown dialect, bad values, ...)."""


class ProcessError(ConformalError):
    """A tool, material or design-of-experiments definition is invalid."""


class StreamError(ConformalError):
    """Sending a program to a machine failed (port, protocol, state file)."""


class OutputError(ConformalError):
    """An output cannot be written where asked (missing folder, a folder, an input, no access)."""
