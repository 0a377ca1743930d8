"""``effects``: the candidate effects of a table (its catalogue and the user's) with their
parameters, required columns, definition and title."""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse

from .common import add_mount_option, input_path, one_line_errors, print_json

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``effects`` to ``subparsers``."""
    p = subparsers.add_parser(
        "effects",
        description="List the candidate effects of the table: the catalogue, the effects of "
        "--catalogue files (.yaml effect files, .py modules) and installed ones (entry point "
        "group turntable_pin.effects), with parameters (name, unit, description), required "
        "columns, definition and title.",
    )
    one_line_errors(p)
    p.add_argument(
        "--urdf", type=input_path, metavar="FILE.urdf", help="the table (default: bundled)"
    )
    p.add_argument(
        "--payload-frame",
        metavar="NAME",
        help="the payload frame of the URDF (default: the only leaf of its chain)",
    )
    add_mount_option(p)
    p.add_argument("--catalogue", action="append", default=[], type=input_path, metavar="FILE",
                   help="your effects (.yaml effect file or .py module); repeatable. A .py "
                   "module is code that runs: it is imported and its methods called (give only "
                   "files you trust; default: the catalogue alone)")  # fmt: skip
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run_effects)


def run_effects(args: argparse.Namespace) -> int:
    from ..measurement.catalogue import catalogue
    from ..measurement.table import measured_table
    from ..measurement.user_effects import describe_effects, load_catalogue
    from .common import table_from_args

    table = measured_table(table_from_args(args))
    effects = (*catalogue(table), *load_catalogue(args.catalogue, table))
    listing = describe_effects(effects, table)
    if args.json:
        print_json({"table": table.label, "base_errors": list(table.base_names),
                    "joints": list(table.joint_names), "effects": listing})  # fmt: skip
        return 0
    print(f"table {table.label}: joints {', '.join(table.joint_names)}; base errors "
          f"{', '.join(table.base_names)}")  # fmt: skip
    for e in listing:
        where = "" if e["source"] == "catalogue" else f"  [{e['source']}]"
        print(f"\n{e['effect']}: {e['title']}{where}")
        print(f"  definition: {e['definition']}")
        if e["required_columns"]:
            print(f"  needs: {', '.join(e['required_columns'])}")
        for p in e["parameters"]:
            print(f"  {p['name']:10s} {p['unit']:18s} {p['description']}")
    return 0
