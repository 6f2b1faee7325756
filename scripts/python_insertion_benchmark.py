#!/usr/bin/env python3
"""Inserting a recording from numpy (the Python module mvog) against the C++ insertion of the
same rays, in one run (BENCHMARKS.md, "The Python module").

mvog_ray_export (src/tools/ray_export.cpp) reads an OctoMap ScanGraph recording, times the C++
insertion of its scans into a new map (Map::insertScan on the scans as read, the fastest of
--repeat in one process) and writes their rays as numpy files; this script then inserts the same
rays from numpy into a new map with mvog.Map.insert_scan, scan by scan, --repeat times, and checks
that both maps are the same bytes. C++ and Python rounds alternate, so that both see the same
load of the machine; each side's figure is its fastest insertion over all rounds.

From a sourced workspace (scripts/common.sh builds it):
  python3 scripts/python_insertion_benchmark.py [--data DIR] [--rounds K] [--repeat K]
      [--resolution R] [--threads N] [RECORDING.graph ...]
Prints one table row per recording and input dtype (float32 is read in place; float64 is
converted to the core's float32 readings).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import mvog

REPO = Path(__file__).resolve().parents[1]
RECORDINGS = ["kurt3d_3scans.graph", "tum_fr2_pioneer_slam2_10frames.graph"]


def ray_export_tool():
    explicit = os.environ.get("MVOG_RAY_EXPORT")
    if explicit:
        return explicit
    for prefix in filter(None, os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep)):
        candidate = Path(prefix) / "lib" / "mvog" / "mvog_ray_export"
        if candidate.is_file():
            return str(candidate)
    sys.exit("mvog_ray_export not found: source the built workspace or set MVOG_RAY_EXPORT")


def cpp_round(tool, recording, out, args):
    printed = subprocess.run(
        [tool, str(recording), str(out), "--resolution", str(args.resolution),
         "--threads", str(args.threads), "--repeat", str(args.repeat)], check=True, capture_output=True, text=True).stdout
    return json.loads(printed)


def scans_of(out, dtype):
    origins = np.load(out / "origins.npy")
    sizes = np.load(out / "scan_sizes.npy")
    hits = np.load(out / "hits.npy").astype(dtype)
    ends = np.cumsum(sizes)
    return [(origin, hits[end - size:end]) for origin, size, end in zip(origins, sizes, ends)]


def python_round(scans, args):
    world = mvog.Map(mvog.MapConfig(resolution=args.resolution))
    insertion = mvog.InsertionConfig(insertion_threads=args.threads)
    start = time.perf_counter()
    for origin, hits in scans:
        world.insert_scan(origin, hits, config=insertion)
    return time.perf_counter() - start, world


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("recordings", nargs="*", default=RECORDINGS)
    parser.add_argument("--data", default=os.environ.get("MVOG_DATA_DIR")
                        or str(REPO.parent / "shared" / "data"))
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=5, help="insertions per round and side")
    parser.add_argument("--resolution", type=float, default=0.1)
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    tool = ray_export_tool()
    print("%-40s %-8s %10s %12s %12s %8s" % ("recording", "input", "readings", "C++ (s)",
                                            "Python (s)", "ratio"))
    for name in args.recordings:
        recording = Path(args.data) / name
        with tempfile.TemporaryDirectory() as directory:
            out = Path(directory)
            cpp_seconds = []
            python_seconds = {np.float32: [], np.float64: []}
            printed = cpp_round(tool, recording, out, args)
            scans = {dtype: scans_of(out, dtype) for dtype in python_seconds}
            cpp_map = (out / "map.mvog").read_bytes()
            for _ in range(args.rounds):
                cpp_seconds.append(cpp_round(tool, recording, out, args)["insert_seconds"])
                for dtype, seconds in python_seconds.items():
                    for _ in range(args.repeat):
                        elapsed, world = python_round(scans[dtype], args)
                        seconds.append(elapsed)
                    if mvog.serialize_map(world) != cpp_map:
                        sys.exit("%s: the map inserted from %s is not the C++ map" %
                                 (name, dtype.__name__))
            for dtype, seconds in python_seconds.items():
                print("%-40s %-8s %10d %12.4f %12.4f %8.3f" % (
                    name, dtype.__name__, printed["readings"], min(cpp_seconds), min(seconds),
                    min(seconds) / min(cpp_seconds)))
    print("fastest of %d alternating rounds of %d insertions each; resolution %g m, %d insertion "
          "thread(s); maps equal byte for byte" % (args.rounds, args.repeat, args.resolution,
                                                   args.threads))


if __name__ == "__main__":
    main()
