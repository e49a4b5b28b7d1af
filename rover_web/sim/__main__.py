"""Run every simulated robot part in one process: python -m rover_web.sim [--help]."""

from __future__ import annotations

import argparse

from . import drone, rover
from .runner import run_nodes

# Each part: add_arguments(parser) and from_arguments(args, context) -> Node.
PARTS = (rover, drone)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m rover_web.sim", description=__doc__)
    for part in PARTS:
        part.add_arguments(parser)
    args = parser.parse_args(argv)
    run_nodes(lambda context: [part.from_arguments(args, context) for part in PARTS])


if __name__ == "__main__":
    main()
