"""``wheelflat-case``: the installed package's case runner (the engine's binary
``wheelflat_case``; see docs/guide/studies.md), with its arguments and standard input
and output."""

import os
import sys

from .run import default_runner


def main():
    runner = default_runner()
    if runner is None:
        print("wheelflat-case: no case runner in this installation", file=sys.stderr)
        return 2
    os.execv(runner, [runner] + sys.argv[1:])


if __name__ == "__main__":
    sys.exit(main())
