"""The exceptions of crease (the native module raises them too)."""


class FileFormatError(OSError, ValueError):
    """A file's content does not follow its format, or its extension names no format crease knows.

    Both an ``OSError`` (a file problem) and a ``ValueError`` (bad input), like
    ``io.UnsupportedOperation``; the message is the CLI's (``FILE: what is wrong``).
    """


def os_error(code: int, message: str) -> OSError:
    """The ``OSError`` subclass Python picks for ``code`` (``FileNotFoundError`` for ENOENT, ...),
    carrying ``errno`` and the CLI's message as it is (``FILE: what the OS said``)."""
    cls = type(OSError(code, ""))
    e = cls(message)
    e.errno = code
    return e
