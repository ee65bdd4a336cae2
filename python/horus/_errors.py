"""horus's exceptions: one class per C++ error code (horus::Errc), each carrying the C++
error's message (str(e)) and its code (e.code, e.g. "type_mismatch")."""


class Error(Exception):
    """Every horus error. `code` is the C++ error code's name."""

    code = "error"


class InvalidNameError(Error, ValueError):
    """A topic name breaks the naming rules."""


class TypeMismatchError(Error, TypeError):
    """The topic already carries another message type."""


class InvalidArgumentError(Error, ValueError):
    """A bad capacity, slot size or other parameter."""


class ConfigMismatchError(Error, ValueError):
    """The topic exists with another capacity or slot size."""


class LimitReachedError(Error, RuntimeError):
    """Too many publishers or subscribers on one topic, or every pool slot is taken."""


class TimeoutError(Error, TimeoutError):  # noqa: A001 (also a builtins.TimeoutError)
    """A blocking call ran out of time."""


class MessageTooLargeError(Error, ValueError):
    """A message does not fit its slot."""


class ConfigError(Error, ValueError):
    """A malformed setting: a configuration file or an environment variable."""


class IoError(Error, OSError):
    """An operating-system call failed."""


class CorruptError(Error, ValueError):
    """Bytes (a file, a recording) are not what their format says."""
