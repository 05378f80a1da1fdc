"""Command line: ``implicit-boundaries`` (or ``python -m implicit_boundaries``).

Subcommands: ``reconstruct IN [IN ...] -o OUT`` (any format pymeshlab reads and writes;
several scans, or an ``.aln``/``.mlp``/``.conf`` alignment, give one merged surface), ``tiled IN... -o
OUT`` (a large scan tile by tile on Dask), ``compare IN
[--truth GT] --report DIR`` (side by side with MeshLab's screened Poisson), ``demo``
(pymeshlab's bunny scan with its holes, reconstructed and compared) and ``info`` (versions,
plugin path, whether it loads). Errors are one line on stderr and exit status 1; ``--verbose``
shows the traceback.
"""
import argparse
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import pymeshlab

from ._plugin import FILTER_NAME, PluginMismatchError, apply, describe_build, load, plugin_build, plugin_path
from .alignment import SUFFIXES as ALIGNMENT_SUFFIXES, read_alignment
from .cloud import add_layer, read_cloud
from .compare import compare
from .options import Normals, SodsOccupancy
from .reconstruct import loops_from_result

DEMO_SCAN = Path(pymeshlab.__file__).parent / "tests" / "sample_meshes" / "bunny10k_textured.obj"


def _scans(inputs, alignment=None) -> list:
    """[(path, matrix or None)] of the command line's inputs: scan files, and alignment files
    (.aln, .mlp, .conf) standing for the scans they list, with their matrices. With `alignment`, each
    scan file gets the matrix that file gives it (matched by file name)."""
    placed = {path.name: matrix for path, matrix in read_alignment(alignment)} if alignment else None
    scans = []
    for name in inputs:
        path = Path(name)
        if path.suffix.lower() in ALIGNMENT_SUFFIXES:
            scans += read_alignment(path)
        elif placed is not None:
            if path.name not in placed:
                raise ValueError(f"{path.name} is not in {alignment}: it lists {', '.join(sorted(placed))}")
            scans.append((path, placed[path.name]))
        else:
            scans.append((path, None))
    return scans


class ProgressBar:
    """A text progress bar on stderr: redrawn in place on a terminal, a line per step elsewhere."""

    def __init__(self, stream=None, width: int = 30):
        self.stream, self.width, self.open = stream or sys.stderr, width, False

    def __call__(self, done: int, total: int, what: str) -> None:
        filled = self.width * done // max(total, 1)
        line = f"[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} {what}"
        if self.stream.isatty():
            self.stream.write(f"\r{line:<{self.width + 50}}")
            self.open = done < total
            if not self.open:
                self.stream.write("\n")
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self) -> None:
        """Ends a line left open (before an error message)."""
        if self.open:
            self.stream.write("\n")
            self.open = False


def _filter_params(args) -> dict:
    """Our filter's parameters given on the command line (others keep their defaults)."""
    params = {name: getattr(args, name)
              for name in ("sods_dilation", "sample_radius", "min_boundary_edges", "boundary_smoothing")
              if getattr(args, name) is not None}
    if args.paper_occupancy:
        params["sods_occupancy"] = SodsOccupancy.SAMPLE_CELLS
    if args.estimate_normals:
        params["normals"] = Normals.ESTIMATE
    if args.viewpoint is not None:
        params["normals"] = Normals.FACING_VIEWPOINT
        params["viewpoint"] = np.array(args.viewpoint, dtype=np.float64)
    return params


def _reconstruct(ms: pymeshlab.MeshSet, args, **params) -> dict:
    load()
    params.update(_filter_params(args))
    if args.resolution is not None:
        params["resolution"] = args.resolution
    return apply(ms, **params)


def _report(result: dict, out: Path, viewpoint=None) -> None:
    loops = loops_from_result(result)
    sizes = ", ".join(str(len(loop)) for loop in loops) or "none"
    if result["normals_estimated"]:
        how = "oriented by propagation" if viewpoint is None else \
            "facing the viewpoint (" + ", ".join(f"{x:g}" for x in viewpoint) + ")"
        print(f"normals estimated, {how}")
    print(f"resolution {result['resolution']} (cell {result['cell_size']:.4g}), "
          f"{result['surface_faces']} faces")
    print(f"{len(loops)} boundary loops kept; edges per loop: {sizes}")
    print(f"wrote {out}")


def cmd_reconstruct(args) -> int:
    ms = pymeshlab.MeshSet()
    scans = _scans(args.input, getattr(args, "alignment", None))  # demo has none
    for path, matrix in scans:
        # Missing normals stay zero: the filter estimates them (facing --viewpoint when given).
        add_layer(ms, read_cloud(path, estimate_normals=False), path.stem, matrix)
    if len(scans) > 1:
        print(f"merging {len(scans)} scans, {sum(ms.mesh(i).vertex_number() for i in range(len(scans)))} samples")
    result = _reconstruct(ms, args, merge_visible_layers=len(scans) > 1)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    ms.save_current_mesh(str(out))
    _report(result, out.resolve(), args.viewpoint)
    return 0


def cmd_tiled(args) -> int:
    from . import tiled
    params = _filter_params(args)
    if params.pop("normals", None) == Normals.ESTIMATE:
        raise ValueError("tiled runs use the scans' own normals, or normals estimated facing --viewpoint: "
                         "oriented by propagation (--estimate-normals), tiles would not agree")
    for name in args.input:
        if Path(name).suffix.lower() in ALIGNMENT_SUFFIXES:
            raise ValueError(f"{name}: tiled runs take point files, not an alignment; merge the aligned scans with "
                             f"'implicit-boundaries reconstruct {name}', or save them as one point file "
                             "(MeshLab: Flatten Visible Layers) and tile that")
    out = Path(args.output)
    if out.suffix.lower() != ".ply":
        raise ValueError(f"{out}: tiled runs write binary PLY, streamed tile by tile: name the output .ply")
    out.parent.mkdir(parents=True, exist_ok=True)
    r = tiled.reconstruct([str(path) for path in args.input], resolution=args.resolution or 0, tiles=args.tiles,
                          tile_cells=args.tile_cells, workers=args.workers, scheduler=args.scheduler,
                          progress=True, output=str(out), **params)
    sizes = ", ".join(str(len(loop)) for loop in r.loops) or "none"
    print(f"\n{r.info['tiles']} tiles (cell {r.info['cell_size']:.4g}, halo {r.info['halo']:.4g}: "
          f"{r.info['halo'] / r.info['sample_spacing']:.0f} spacings), {r.info['face_count']} faces")
    print(f"{len(r.loops)} boundary loops kept; edges per loop: {sizes}")
    print(f"wrote {out.resolve()}")
    return 0


def _compare(args, input, truth) -> int:
    bar = ProgressBar()
    args.progress = bar  # main() closes it before an error message
    table = compare(input, truth, resolution=args.resolution or 0, depth=args.depth, trim_quantile=args.trim_quantile,
                    poisson_threads=args.poisson_threads, params=_filter_params(args), report=args.report,
                    progress=bar)
    print(table.table())
    print(f"report: {table.report.resolve()}")
    return 0


def cmd_compare(args) -> int:
    return _compare(args, Path(args.input), None if args.truth is None else Path(args.truth))


def cmd_demo(args) -> int:
    print(f"input: {DEMO_SCAN} as MeshLab loads it (pymeshlab's Stanford bunny: vertices, normals and "
          f"triangles; 5 holes at its base)")
    args.input = [DEMO_SCAN]
    cmd_reconstruct(args)
    print("comparing with MeshLab's screened Poisson, the scan's own mesh as ground truth")
    return _compare(args, DEMO_SCAN, DEMO_SCAN)


def cmd_info(args) -> int:
    print(f"pymeshlab {metadata.version('pymeshlab')} (plugin built for 2025.7.post1)")
    print(f"numpy {np.__version__}")
    for name in ("pyvista", "vtk", "matplotlib"):  # needed for the pictures of a comparison report
        try:
            print(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            print(f"{name}: not installed (compare --report needs it)")
    try:
        print(f"plugin {plugin_path()}: built for {describe_build(plugin_build(plugin_path()))}")
        path = load()
    except (FileNotFoundError, PluginMismatchError, pymeshlab.PyMeshLabException) as e:  # diagnose, don't crash
        print(f"plugin: not loadable: {e}")
        return 1
    print(f"plugin {path}: loads, filter '{FILTER_NAME}' available")
    return 0


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="implicit-boundaries", description=__doc__.split("\n")[0])
    p.add_argument("--verbose", action="store_true", help="show tracebacks on errors")
    sub = p.add_subparsers(dest="command", required=True)

    def options(q):
        q.add_argument("--resolution", type=int, help="cells along the longest side (default 0: from the sample spacing)")
        q.add_argument("--sample-radius", type=float, help="tangent disk radius in sample spacings (default 1.25)")
        q.add_argument("--sods-dilation", type=int, help="rings of neighbour cells added to the SODS (default 0)")
        q.add_argument("--min-boundary-edges", type=int,
                       help="fill holes whose loops have fewer edges (default 12; 0 keeps every hole)")
        q.add_argument("--boundary-smoothing", type=int, help="smoothing passes along each loop (default 4; 0 = off)")
        q.add_argument("--paper-occupancy", action="store_true",
                       help="SODS from the cells holding samples, as in the paper (use with --sods-dilation 1)")
        q.add_argument("--estimate-normals", action="store_true", help="ignore the input's normals")
        q.add_argument("--viewpoint", type=float, nargs=3, metavar=("X", "Y", "Z"),
                       help="estimate normals facing this scanner position (one range scan)")

    r = sub.add_parser("reconstruct", help="reconstruct point cloud files into a mesh file")
    r.add_argument("input", nargs="+",
                   help="a scan, or several (merged into one surface), or a MeshLab .aln / .mlp project / "
                        "Stanford .conf alignment standing for the scans it lists, each placed by its matrix")
    r.add_argument("--alignment", metavar="FILE",
                   help="a MeshLab .aln or .mlp or Stanford .conf file that places the scans given (by file name)")
    r.add_argument("-o", "--output", required=True)
    options(r)
    r.set_defaults(run=cmd_reconstruct)

    t = sub.add_parser("tiled", help="reconstruct a large scan tile by tile on Dask (local workers or a cluster)")
    t.add_argument("input", nargs="+", help="point files with normals (binary .ply and .las/.laz read in chunks; "
                                            "any other format pymeshlab reads), or --viewpoint for normals to face")
    t.add_argument("-o", "--output", required=True)
    t.add_argument("--tiles", type=int, help="at least this many tiles (default: tiles of --tile-cells cells a side)")
    t.add_argument("--tile-cells", type=int, default=512, help="lattice cells along a tile's side (default 512)")
    engine = t.add_mutually_exclusive_group()
    engine.add_argument("--workers", type=int, help="local Dask worker processes (default: the cores)")
    engine.add_argument("--scheduler", metavar="ADDRESS",
                        help="an existing Dask scheduler, e.g. tcp://host:8786 (each worker needs this package)")
    options(t)
    t.set_defaults(run=cmd_tiled)

    def comparison(q, report):
        q.add_argument("--report", required=report is None, default=report,
                       help="folder for report.html, its pictures and each method's mesh")
        q.add_argument("--depth", type=int, help="screened Poisson depth (default: 2^depth nearest our resolution)")
        q.add_argument("--trim-quantile", type=float, default=0.05,
                       help="Poisson vertices below this density quantile are removed (default 0.05)")
        q.add_argument("--poisson-threads", type=int, default=1, help="screened Poisson threads (default 1)")

    c = sub.add_parser("compare", help="side by side with MeshLab's screened Poisson: table, pictures, report")
    c.add_argument("input")
    c.add_argument("--truth", help="ground-truth mesh: adds chamfer, spurious/missing area, boundary distance")
    comparison(c, None)
    options(c)
    c.set_defaults(run=cmd_compare)

    d = sub.add_parser("demo", help="reconstruct pymeshlab's bunny scan with its holes and compare")
    d.add_argument("-o", "--output", default="out/bunny_with_boundaries.ply")
    comparison(d, "out/bunny_report")
    options(d)
    d.set_defaults(run=cmd_demo)

    i = sub.add_parser("info", help="versions, plugin path, whether it loads")
    i.set_defaults(run=cmd_info)
    return p


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    try:
        return args.run(args)
    except (pymeshlab.PyMeshLabException, OSError, ValueError) as e:
        if getattr(args, "progress", None):
            args.progress.close()
        if args.verbose:
            raise
        # pymeshlab's messages span lines; the error stays one line.
        message = "; ".join(line.strip() for line in str(e).splitlines() if line.strip())
        print(f"implicit-boundaries: error: {message}", file=sys.stderr)
        return 1
