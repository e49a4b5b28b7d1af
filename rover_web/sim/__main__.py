"""Run every simulated robot part in one process: python -m rover_web.sim [--help]."""

from __future__ import annotations

import argparse

from . import camera, drone, light_buoy, rover
from .runner import run_nodes

# Each part: add_arguments(parser) and from_arguments(args, context) -> Node.
PARTS = (rover, light_buoy, drone, camera)


def part_name(part) -> str:
    return part.__name__.rsplit(".", 1)[-1]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m rover_web.sim", description=__doc__)
    parser.add_argument("--only", action="append", choices=[part_name(p) for p in PARTS], metavar="PART",
                        help="run only this part (repeatable; default all: "
                             + ", ".join(part_name(p) for p in PARTS) + ")")
    for part in PARTS:
        part.add_arguments(parser)
    args = parser.parse_args(argv)
    parts = [p for p in PARTS if not args.only or part_name(p) in args.only]
    run_nodes(lambda context: [part.from_arguments(args, context) for part in parts])


if __name__ == "__main__":
    main()
