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


class CommandError(RuntimeError):
    """A ``crease`` command line run by :func:`crease.command` (or a task of
    :func:`crease.batch`) failed.

    ``code`` is the CLI's exit code (1: the input or the computation failed, 2: a usage error such
    as an unknown option) and ``message`` its message (``FILE: what is wrong``; empty for a usage
    error, whose text the CLI has printed on stderr).
    """

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message or f"the command line was refused (exit code {code})")
        self.code = code
        self.message = message
