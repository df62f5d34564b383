"""`doe design ...` writes a run sheet; `doe analyze results.csv` prints the effects, writes
the half-normal plot and reports the models and the optimum (METHODS section 2)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from freecad_conformal.errors import ProcessError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="doe_command", metavar="ACTION")
    sub.required = True
    design = sub.add_parser("design", help="a 2^k or 2^(k-p) design and its run sheet")
    design.add_argument("-k", "--factors", type=int, default=None,
                        help="number of factors A, B, C, ... coded -1/+1")
    design.add_argument("--factor", action="append", default=[], metavar="SPEC",
                        help="NAME:LOW:HIGH[:LABEL[:UNIT]], e.g. 'A:231:495:UV power:mW' or "
                             "'C:cured resin:plastic film:base' (repeat per factor)")
    design.add_argument("-g", "--generator", action="append", default=[],
                        help="generator 'D=ABC' or defining relation 'I=ABCD' (repeatable)")
    design.add_argument("-r", "--replicates", type=int, default=1)
    design.add_argument("--centre", type=int, default=0, help="centre points (numeric factors)")
    design.add_argument("--seed", type=int, default=None, help="seed of the random run order")
    design.add_argument("--no-randomize", action="store_true", help="keep standard order")
    design.add_argument("--response", default="y", help="response column name")
    design.add_argument("--sheet", type=Path, help="write the run sheet CSV here")
    design.add_argument("--save", type=Path, help="write the design JSON here")
    design.add_argument("--json", action="store_true", help="print the design as JSON")

    analyze = sub.add_parser("analyze", help="effects, models and optimum from results")
    analyze.add_argument("results", type=Path, help="CSV: factor columns A, B, ... and results")
    analyze.add_argument("--response", help="response column, one row per replicate")
    analyze.add_argument("--mean", help="per-run mean column (published summaries)")
    analyze.add_argument("--ln-s2", dest="ln_s2", help="per-run ln s² column (with --mean)")
    analyze.add_argument("--s2", help="per-run s² column (with --mean)")
    analyze.add_argument("--design", type=Path, help="design JSON: real levels of the factors")
    analyze.add_argument("--location", default="lenth",
                         help="location terms: 'D,A', 'lenth', 'lenth-sme' or 'none'")
    analyze.add_argument("--dispersion", default="lenth",
                         help="dispersion terms: 'B,D,C', 'lenth', 'lenth-sme' or 'none'")
    analyze.add_argument("--goal", choices=("larger", "smaller", "nominal"), default="larger")
    analyze.add_argument("--target", type=float, help="target of a nominal-the-better response")
    analyze.add_argument("--alpha", type=float, default=0.05, help="Lenth significance level")
    analyze.add_argument("--response-scale", type=float,
                         help="real value of response 1.0 (e.g. Vmax 3.556 for V/Vmax)")
    analyze.add_argument("--response-unit", default="", help="unit after scaling, e.g. mm/s")
    analyze.add_argument("--plot", type=Path,
                         help="half-normal plot PNG (default: beside the results file)")
    analyze.add_argument("--no-plot", action="store_true")
    analyze.add_argument("--json", action="store_true", help="print the analysis as JSON")
    analyze.add_argument("--save-tool", metavar="TOOL_ID",
                         help="store the optimum in this tool's settings (user library)")
    analyze.add_argument("--material", help="material name for --save-tool")
    analyze.add_argument("--user-dir", type=Path, help="user tool folder for --save-tool")


def run(args: argparse.Namespace) -> int:
    if args.doe_command == "design":
        return _design(args)
    return _analyze(args)


def _parse_factor(spec: str):
    from freecad_conformal.process.doe.design import Factor

    parts = spec.split(":")
    if len(parts) < 3 or len(parts) > 5:
        raise ProcessError(f"factor {spec!r} must be NAME:LOW:HIGH[:LABEL[:UNIT]]")

    def level(text: str):
        try:
            return float(text)
        except ValueError:
            return text.strip()

    low, high = level(parts[1]), level(parts[2])
    if isinstance(low, float) != isinstance(high, float):
        raise ProcessError(f"factor {spec!r}: both levels must be numbers or both texts")
    return Factor(parts[0].strip().upper(), parts[3] if len(parts) > 3 else "", low, high,
                  parts[4] if len(parts) > 4 else "")


def _design(args: argparse.Namespace) -> int:
    from freecad_conformal.fileio import write_text_atomic
    from freecad_conformal.process.doe.design import Design
    from freecad_conformal.process.doe.sheet import run_sheet_text, write_run_sheet
    from freecad_conformal.process.doe.words import roman

    if args.factor:
        factors = [_parse_factor(spec) for spec in args.factor]
    elif args.factors:
        factors = args.factors
    else:
        raise ProcessError("give the factors: -k N, or --factor NAME:LOW:HIGH per factor")
    design = Design.build(factors, args.generator, replicates=args.replicates,
                          centre_points=args.centre, seed=args.seed,
                          randomize=not args.no_randomize, response=args.response)
    if args.save:
        write_text_atomic(args.save, json.dumps(design.to_dict(), indent=2) + "\n")
    if args.sheet:
        write_run_sheet(design, args.sheet)
    if args.json:
        data = design.to_dict()
        data.update(title=design.title(), resolution=design.resolution,
                    defining_relation=[("-" if s < 0 else "") + w
                                       for w, s in design.defining_relation],
                    aliases=[str(a) for a in design.alias_structure()])
        print(json.dumps(data, indent=2))
        return 0
    print(design.title())
    if design.generators:
        relation = " = ".join(["I"] + [("-" if s < 0 else "") + w
                                       for w, s in design.defining_relation])
        print(f"generators: {', '.join(map(str, design.generators))}; defining relation {relation}; "
              f"resolution {roman(design.resolution)}")
        print("aliases: " + ", ".join(str(a) for a in design.alias_structure()))
    for path, what in ((args.sheet, "run sheet"), (args.save, "design")):
        if path:
            print(f"wrote {what} {path}")
    if not args.sheet:
        print(run_sheet_text(design), end="")
    return 0


def _terms(text: str):
    lowered = text.strip().lower()
    if lowered in ("none", ""):
        return None
    if lowered in ("lenth", "lenth-sme"):
        return lowered
    return [word.strip() for word in text.split(",") if word.strip()]


def _analyze(args: argparse.Namespace) -> int:
    from freecad_conformal.process.doe.analysis import analyze
    from freecad_conformal.process.doe.design import Design
    from freecad_conformal.process.doe.effects import RunData
    from freecad_conformal.process.doe.report import effects_table
    from freecad_conformal.process.doe.sheet import read_table

    design = None
    if args.design:
        try:
            design = Design.from_dict(json.loads(args.design.read_text(encoding="utf-8")),
                                      f"design {args.design.name}")
        except (OSError, ValueError) as exc:        # ValueError: bad JSON, not UTF-8
            raise ProcessError(f"cannot read design {args.design}: {exc}") from exc
    if args.mean:
        if args.response:
            raise ProcessError("give either --response (replicates) or --mean (summaries)")
        columns = [args.mean] + [c for c in (args.ln_s2, args.s2) if c]
        data = RunData.from_summaries(read_table(args.results, columns, design), args.mean,
                                      args.ln_s2, args.s2)
    else:
        response = args.response or (design.response if design else None)
        if not response:
            raise ProcessError("name the response column: --response NAME (or --mean COL "
                               "--ln-s2 COL for per-run summaries)")
        data = RunData.from_replicates(read_table(args.results, [response], design), response)
    result = analyze(data, _terms(args.location), _terms(args.dispersion), args.goal,
                     args.target, args.alpha, design, args.response_scale, args.response_unit)
    plot = None
    if not args.no_plot:
        from freecad_conformal.process.doe.plot import write_half_normal_png

        plot = args.plot or args.results.with_name(args.results.stem + "_halfnormal.png")
        write_half_normal_png(result, plot)
    if args.save_tool:
        _save_tool(args, result, design)
    if args.json:
        data_out = result.to_dict()
        data_out["plot"] = str(plot) if plot else None
        print(json.dumps(data_out, indent=2))
    else:
        print(effects_table(result, design))
        if plot:
            print(f"half-normal plot: {plot}")
    return 0


def _save_tool(args: argparse.Namespace, result, design) -> None:
    from freecad_conformal.process.doe.to_tool import save_optimum
    from freecad_conformal.process.library import ToolLibrary

    if not args.material:
        raise ProcessError("--save-tool needs --material NAME")
    library = ToolLibrary.load(user_dir=args.user_dir)
    save_optimum(library, args.save_tool, args.material, result, design,
                 study=args.results.stem)
    library.save()
