"""The exceptions demstudy raises, in one place (the CLI maps each to an exit code).

``SceneError`` (invalid scene, :mod:`demstudy.scene.load`) and ``UnsupportedByEngine`` (an
engine cannot express what the scene or a run option asks for) are raised before any engine
starts (exit 2); ``EngineError`` is a failure during a run (exit 1; its subclass
``RunRefused``, also ``demstudy.io.checksum.DamagedCheckpoint``, means nothing ran: exit 2),
``RunStopped`` a run that stopped on request after a checkpoint (exit 3, continue with
``--resume``).
"""

from __future__ import annotations


class UnsupportedByEngine(ValueError):
    """The scene or a run option asks for something this engine cannot express exactly.

    ``engine``, ``field_name`` (the scene field or option), ``value`` and the reason (what
    is allowed instead) are attributes and in the message."""

    def __init__(self, engine: str, field_name: str, value: object, reason: str):
        self.engine, self.field_name, self.value, self.reason = engine, field_name, value, reason
        super().__init__(f"unsupported by {engine}: {field_name} = {value!r}: {reason}")


class EngineError(RuntimeError):
    """An engine failed; the message says what the engine reported and where."""


#: how a single run's stop message ends (a sweep, which resumes by itself, drops it)
RESUME_ADVICE = ": run the same command again with --resume to continue"


class RunStopped(EngineError):
    """The run stopped on request (Ctrl-C, wall-clock limit) after writing a checkpoint; its
    message ends with ``RESUME_ADVICE``."""


class RunAborted(EngineError):
    """A second Ctrl-C aborted the run without a new checkpoint (exit 130); the last one
    written, if any, stays and ``--resume`` continues from it."""


class StatisticUnavailable(ValueError):
    """A statistic cannot be computed from what it is given (no frames, no collision log, the
    wrong dimension): nothing was computed (exit 2 on the command line)."""


class BadOption(ValueError):
    """A command-line option or keyword argument has a value that is not allowed: its
    ``option`` name, the ``value`` and what is allowed are attributes and in the message
    (exit 2: nothing ran)."""

    def __init__(self, option: str, value: object, allowed: str):
        self.option, self.value = option, value
        super().__init__(f"{option} = {value!r}: {allowed}")


class NotComparable(ValueError):
    """Runs that cannot be compared (``demstudy compare``): a file without profiles, an
    unknown field, different dimensions or profile axes, bins that do not overlap; the
    message names the files and the field. Nothing was computed (exit 2)."""


class BadInputFile(ValueError):
    """A file given to read (a results file, a LAMMPS dump) is damaged, not of the expected
    kind or lacks what is needed (a dump without z or with scaled coordinates); the message
    names the file and what is missing. Nothing was computed (exit 2)."""


class RunRefused(EngineError):
    """The engine refused the scene or the options (reported by an engine's child process)."""


__all__ = ["BadInputFile", "BadOption", "EngineError", "NotComparable", "RunAborted", "RunRefused",
           "RunStopped",
           "StatisticUnavailable",
           "UnsupportedByEngine"]
