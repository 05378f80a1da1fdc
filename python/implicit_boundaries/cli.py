"""Command line: ``implicit-boundaries`` (or ``python -m implicit_boundaries``).

Subcommands: ``reconstruct IN -o OUT`` (any format pymeshlab reads and writes), ``demo``
(pymeshlab's bunny scan with its holes) and ``info`` (versions, plugin path, whether it loads).
Errors are one line on stderr and exit status 1; ``--verbose`` shows the traceback.
"""
import argparse
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import pymeshlab

from ._plugin import FILTER_NAME, apply, load
from .reconstruct import loops_from_result

DEMO_SCAN = Path(pymeshlab.__file__).parent / "tests" / "sample_meshes" / "bunny10k_textured.obj"


def _point_cloud(ms: pymeshlab.MeshSet, path: Path) -> None:
    """Loads `path` and replaces it by its vertices and normals only (faces ignored)."""
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    m.compact()
    points = pymeshlab.Mesh(vertex_matrix=m.vertex_matrix(), v_normals_matrix=m.vertex_normal_matrix())
    ms.clear()
    ms.add_mesh(points, path.stem)


def _reconstruct(ms: pymeshlab.MeshSet, args) -> dict:
    load()
    params = {name: getattr(args, name)
              for name in ("resolution", "sods_dilation", "sample_radius", "min_boundary_edges", "boundary_smoothing")
              if getattr(args, name) is not None}
    if args.paper_occupancy:
        params["sods_occupancy"] = "Sample cells (paper)"
    return apply(ms, normals="Estimate" if args.estimate_normals else "Use layer normals", **params)


def _report(result: dict, out: Path) -> None:
    loops = loops_from_result(result)
    sizes = ", ".join(str(len(loop)) for loop in loops) or "none"
    print(f"resolution {result['resolution']} (cell {result['cell_size']:.4g}), "
          f"{result['surface_faces']} faces")
    print(f"{len(loops)} boundary loops kept; edges per loop: {sizes}")
    print(f"wrote {out}")


def cmd_reconstruct(args) -> int:
    ms = pymeshlab.MeshSet()
    path = Path(args.input)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    _point_cloud(ms, path)
    result = _reconstruct(ms, args)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    ms.save_current_mesh(str(out))
    _report(result, out.resolve())
    return 0


def cmd_demo(args) -> int:
    print(f"input: vertices and normals of {DEMO_SCAN} (pymeshlab's Stanford bunny, 5 holes at its base)")
    args.input = DEMO_SCAN
    return cmd_reconstruct(args)


def cmd_info(args) -> int:
    print(f"pymeshlab {metadata.version('pymeshlab')} (plugin built for 2025.7.post1)")
    print(f"numpy {np.__version__}")
    try:
        path = load()
    except (FileNotFoundError, pymeshlab.PyMeshLabException) as e:  # diagnose, don't crash
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

    r = sub.add_parser("reconstruct", help="reconstruct a point cloud file into a mesh file")
    r.add_argument("input")
    r.add_argument("-o", "--output", required=True)
    options(r)
    r.set_defaults(run=cmd_reconstruct)

    d = sub.add_parser("demo", help="reconstruct pymeshlab's bunny scan with its holes")
    d.add_argument("-o", "--output", default="out/bunny_with_boundaries.ply")
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
        if args.verbose:
            raise
        print(f"implicit-boundaries: error: {e}", file=sys.stderr)
        return 1
