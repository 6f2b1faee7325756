#!/usr/bin/python3
"""The tables of BENCHMARKS.md from the outputs of scripts/benchmarks.sh.

usage: benchmark_tables.py OUT   (the directory benchmarks.sh wrote)
"""
import glob
import json
import os
import sys


def load(path):
    with open(path) as f:
        return json.load(f)


def by_resolution(entries, backend=None):
    return {
        e["resolution"]: e for e in entries if backend is None or e.get("backend") == backend
    }


def file_name(path, prefix):
    return os.path.basename(path)[len(prefix):-len(".json")]


def row(cells):
    return "| " + " | ".join(cells) + " |"


def table(header, rows):
    lines = [row(header), row(["---"] * len(header))]
    lines.extend(row(r) for r in rows)
    return "\n".join(lines)


def percent(value):
    return f"{value:.1f}"


def megabytes(value):
    return f"{value / 1e6:.2f}"


def main(out):
    runs = {file_name(p, "all_"): load(p) for p in sorted(glob.glob(f"{out}/all_*.json"))}
    paper = {file_name(p, "paper_"): load(p) for p in glob.glob(f"{out}/paper_*.json")}
    threaded = {file_name(p, "threads2_"): load(p) for p in glob.glob(f"{out}/threads2_*.json")}
    if not runs:
        sys.exit(f"benchmark_tables.py: no all_*.json in {out}")

    quality, speed, memory, threads = [], [], [], []
    for name, run in runs.items():
        mvog_quality = by_resolution(run["quality"], "mvog")
        octomap_quality = by_resolution(run["quality"], "octomap")
        paper_quality = by_resolution(paper[name]["quality"], "mvog") if name in paper else {}
        results = {b: by_resolution(run["results"], b) for b in ("mvog", "octomap", "walk")}
        comparison = by_resolution(run["comparison"])
        table_one = by_resolution(run["table_one"])
        for resolution in sorted(mvog_quality, reverse=True):
            m, o = mvog_quality[resolution], octomap_quality[resolution]
            p = paper_quality.get(resolution)
            quality.append([
                name, f"{resolution:g}",
                percent(m["endpoints_occupied_percent"]), percent(o["endpoints_occupied_percent"]),
                percent(p["endpoints_occupied_percent"]) if p else "-",
                percent(m["along_rays_free_percent"]), percent(o["along_rays_free_percent"]),
                percent(p["along_rays_free_percent"]) if p else "-",
                percent(m["far_unknown_percent"]), percent(o["far_unknown_percent"]),
            ])
            mv, oc, walk = (results[b][resolution] for b in ("mvog", "octomap", "walk"))
            speed.append([
                name, f"{resolution:g}", f"{mv['readings']:,}",
                f"{mv['insert_seconds']:.3f}", f"{oc['insert_seconds']:.3f}",
                f"{walk['insert_seconds']:.3f}",
                f"{mv['readings_per_second'] / 1e6:.2f}",
                f"{comparison[resolution]['readings_per_second_ratio']:.1f}x",
                f"{walk['mvog_time_ratio']:.2f}x",
            ])
            memory.append([
                name, f"{resolution:g}", megabytes(mv["memory_bytes"]),
                megabytes(oc["memory_bytes"]), f"{comparison[resolution]['memory_ratio']:.3f}x",
                megabytes(table_one[resolution]["mvog_bytes"]),
                megabytes(table_one[resolution]["octomap_bytes"]),
                megabytes(mv["file_bytes"]), megabytes(oc["full_file_bytes"]),
            ])
        if name in threaded:
            one = results["mvog"][0.05]
            two = by_resolution(threaded[name]["results"], "mvog")[0.05]
            threads.append([
                name, f"{one['insert_seconds']:.3f}", f"{two['insert_seconds']:.3f}",
                f"{one['insert_seconds'] / two['insert_seconds']:.2f}x",
                "yes" if one["map_checksum"] == two["map_checksum"] else "NO",
            ])

    def read_text(name):
        path = f"{out}/{name}"
        return open(path).read().strip() if os.path.exists(path) else "?"

    repeat = next(iter(runs.values())).get("repeat", 1)
    print(f"Load average (1, 5, 15 min) before: {read_text('load_average_before')}, "
          f"after: {read_text('load_average_after')}; timings: the fastest of {repeat} "
          "insertion(s) per backend.\n")
    print("### Quality (% of the sampled points)\n")
    print(table(["file", "res (m)", "ends occupied: MVOG", "OctoMap", "paper model",
                 "along free: MVOG", "OctoMap", "paper model", "far unknown: MVOG", "OctoMap"],
                quality))
    print("\n### Speed (one thread)\n")
    print(table(["file", "res (m)", "readings", "MVOG (s)", "OctoMap (s)", "walk (s)",
                 "MVOG M readings/s", "MVOG / OctoMap speed", "MVOG / walk time"], speed))
    print("\n### Memory (MB)\n")
    print(table(["file", "res (m)", "MVOG held", "OctoMap held (pruned)", "MVOG / OctoMap",
                 "Table I: MVOG", "Table I: OctoMap", "MVOG file", "OctoMap .ot file"], memory))
    print("\n### Threads (0.05 m)\n")
    print(table(["file", "1 thread (s)", "2 threads (s)", "speed-up", "same map"], threads))
    instructions = []
    for path in sorted(glob.glob(f"{out}/instructions_mvog_*")):
        name = os.path.basename(path)[len("instructions_mvog_"):]
        counts = {b: int(read_text(f"instructions_{b}_{name}"))
                  for b in ("mvog", "octomap", "walk")}
        instructions.append([
            name, f"{counts['mvog'] / 1e6:,.0f} M", f"{counts['octomap'] / 1e6:,.0f} M",
            f"{counts['walk'] / 1e6:,.0f} M", f"{counts['octomap'] / counts['mvog']:.2f}x",
            f"{counts['mvog'] / counts['walk']:.2f}x",
        ])
    if instructions:
        print("\n### Instructions retired by the insertion (callgrind, 0.05 m, one thread)\n")
        print(table(["file", "MVOG", "OctoMap", "walk", "OctoMap / MVOG", "MVOG / walk"],
                    instructions))
    microbench = f"{out}/microbench.json"
    if os.path.exists(microbench):
        print("\n### Micro-benchmarks (mvog_microbench)\n")
        rows = [[b["name"], f"{b['real_time']:.3g} {b['time_unit']}",
                 f"{b['cpu_time']:.3g} {b['time_unit']}"]
                for b in load(microbench)["benchmarks"]]
        print(table(["benchmark", "wall time", "CPU time"], rows))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
