"""Run every simulated robot part in one process: python -m rover_web.sim [--help]."""

from __future__ import annotations

import argparse

from . import camera, drone, light_buoy, rover
from .robots import KIND_PARTS, SPACING_EAST_M, plan, robots_argument
from .runner import run_nodes

# Each part: add_arguments(parser) and from_arguments(args, context, namespace=..., east_offset_m=...) -> Node.
PARTS = (rover, light_buoy, drone, camera)

ROBOTS_HELP = (
    "run these robots, each in namespace /NAME (its topics become /NAME/cmd_vel, /NAME/odom, ...). "
    "NAME:KIND sets the kind; otherwise a name starting with a kind has that kind (boat, rover2, "
    "drone_a), any other name is a rover. Kinds run: "
    + "; ".join(f"{kind}: {' + '.join(parts)}" for kind, parts in KIND_PARTS.items())
    + f". Driving robots start {SPACING_EAST_M:g} m east of each other. Every part option applies to "
    "every robot. Default: one robot, un-namespaced, with every part")


def part_name(part) -> str:
    return part.__name__.rsplit(".", 1)[-1]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m rover_web.sim", description=__doc__)
    parser.add_argument("--robots", type=robots_argument, metavar="NAME[:KIND][,...]", help=ROBOTS_HELP)
    parser.add_argument("--only", action="append", choices=[part_name(p) for p in PARTS], metavar="PART",
                        help="run only this part (repeatable; default all: "
                             + ", ".join(part_name(p) for p in PARTS)
                             + "); with --robots, only this part of each robot that has it")
    for part in PARTS:
        part.add_arguments(parser)
    args = parser.parse_args(argv)
    by_name = {part_name(p): p for p in PARTS}
    if args.robots is None:
        placements = [(p, "/", 0.0, "") for p in PARTS if not args.only or part_name(p) in args.only]
    else:
        placements = [(by_name[p.part], p.namespace, p.east_offset_m, p.kind) for p in plan(args.robots, args.only)]
        if not placements:
            parser.error("--only leaves none of these robots anything to run")
    run_nodes(lambda context: [part.from_arguments(args, context, namespace=namespace, east_offset_m=offset,
                                                   **({"kind": kind} if part is rover else {}))
                               for part, namespace, offset, kind in placements])


if __name__ == "__main__":
    main()
