"""The filter's total time at its defaults on bun_zipper and the 1M-sample synthetic scan (as
points with normals), and on raw range scans as MeshLab opens them (bun045 and chin of the
Stanford bunny's scans, their triangles given), for two or more builds of the plugin, alternated so that each round runs every build back to back
(this machine's speed drifts by up to 30% within a minute).

An older commit's plugin, for the "no loss elsewhere" check of issue 18 (the commit before its
work was b963eda):

    git worktree add /tmp/base b963eda
    cmake -S /tmp/base -B /tmp/base/build -G Ninja -DIB_BUILD_TESTS=OFF \\
      -DMESHLAB_SOURCE_DIR="$(.ci/meshlab-source)" && cmake --build /tmp/base/build
    python bench/speed.py --plugins <the .so it built> build/meshlab-2025.07d/libfilter_implicit_boundaries.so

Each build runs in its own process (pymeshlab loads one plugin of a name). Prints per case and
build the median seconds of each round, the stages' seconds, loops and faces, then each build's
time over the first build's, the median over the rounds.
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
CASES = {"bun_zipper": 5, "synthetic 1M": 1, "bun045 mesh": 1, "chin mesh": 1}  # case: runs per round (the median is kept)


def run_one(plugin, case, runs):
    """In this process: the filter `runs` times on `case` with the plugin at `plugin`."""
    import pymeshlab
    sys.path.insert(0, str(BENCH))
    pymeshlab.load_plugin(plugin)
    faces = None
    if case == "synthetic 1M":
        from extraction import synthetic_scan
        points, normals = synthetic_scan(1_000_000)
    elif case.endswith(" mesh"):
        from corpus import DEFAULT_DATA, load_case
        points, normals, faces = load_case(DEFAULT_DATA / "bunny_scans" / f"{case.split()[0]}.ply")
    else:
        from corpus import DEFAULT_DATA, load_case
        points, normals, _ = load_case(DEFAULT_DATA / f"{case}.ply")
    arrays = dict(vertex_matrix=points, v_normals_matrix=normals)
    if faces is not None:
        arrays["face_matrix"] = faces
    seconds = []
    for _ in range(runs):
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(**arrays), "scan")
        t = time.perf_counter()
        out = ms.apply_filter("generate_surface_reconstruction_implicit_with_boundaries")
        seconds.append(time.perf_counter() - t)
    print(json.dumps({"seconds": float(np.median(seconds)), "loops": int(out["boundary_loops"]),
                      "faces": ms.current_mesh().face_number(),
                      "stages": {k[8:]: round(float(v), 3) for k, v in out.items() if str(k).startswith("seconds_")}}))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--plugins", nargs="+", required=True, help="plugin files; ratios are over the first")
    p.add_argument("--rounds", type=int, default=2)
    p.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    p.add_argument("--one", nargs=2, help=argparse.SUPPRESS)  # plugin, case: a child process
    args = p.parse_args(argv)
    if args.one:
        return run_one(args.one[0], args.one[1], CASES[args.one[1]])
    print("| case | plugin | round | seconds | normals / implicit / sods / extraction / boundaries (s) | loops | faces |")
    print("|---|---|---|---|---|---|---|")
    ratios = {}
    for case in args.cases:
        for round_ in range(args.rounds):
            first = None
            for plugin in args.plugins:
                child = subprocess.run([sys.executable, __file__, "--plugins", plugin, "--one", plugin, case],
                                       capture_output=True, text=True, check=True)
                r = json.loads(child.stdout.strip().splitlines()[-1])
                s = r["stages"]
                print(f"| {case} | {plugin} | {round_ + 1} | {r['seconds']:.2f} | {s['normals']} / {s['implicit']} / "
                      f"{s['sods']} / {s['extraction']} / {s['boundaries']} | {r['loops']} | {r['faces']} |", flush=True)
                first = first or r["seconds"]
                ratios.setdefault((case, plugin), []).append(r["seconds"] / first)
    print("\n| case | plugin | time over the first plugin's (median of the rounds) |\n|---|---|---|")
    for (case, plugin), values in ratios.items():
        print(f"| {case} | {plugin} | {np.median(values):.2f} |")


if __name__ == "__main__":
    main()
