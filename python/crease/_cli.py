"""The ``crease`` console command installed with the package: the CLI's own code, run in this
process (the same options, output and exit codes as the binary built with cargo)."""

import signal
import sys

from . import _crease


def main() -> None:
    # Ctrl-C stops the command at once, as it stops the binary (Python would otherwise wait
    # for the computation to return before raising KeyboardInterrupt).
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.exit(_crease.command(sys.argv[1:], False))


if __name__ == "__main__":
    main()
