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


def by_backend(run):
    """An mvog_bench run's MVOG and OctoMap quality, each backend's results and the comparison,
    each by resolution."""
    return (by_resolution(run["quality"], "mvog"), by_resolution(run["quality"], "octomap"),
            {b: by_resolution(run["results"], b) for b in ("mvog", "octomap", "bonxai", "walk")},
            by_resolution(run["comparison"]))


BONXAI_QUALITY = ["ends occupied: Bonxai", "along free: Bonxai", "far unknown: Bonxai"]
BONXAI_SPEED = ["Bonxai (s)", "MVOG / Bonxai speed"]
BONXAI_MEMORY = ["Bonxai held", "MVOG / Bonxai memory"]


def bonxai_columns(run, resolution):
    """Bonxai's figures at one resolution of an mvog_bench run, when it ran (mvog_bench built with
    MVOG_PEERS_DIR): its quality, time, memory and MVOG / Bonxai ratios, each a table cell."""
    quality = by_resolution(run["quality"], "bonxai").get(resolution)
    result = by_resolution(run["results"], "bonxai").get(resolution)
    ratios = by_resolution(run.get("bonxai_comparison", [])).get(resolution)
    if not (quality and result and ratios):
        return dict.fromkeys(BONXAI_QUALITY + BONXAI_SPEED + BONXAI_MEMORY, "-")
    return {
        "ends occupied: Bonxai": percent(quality["endpoints_occupied_percent"]),
        "along free: Bonxai": percent(quality["along_rays_free_percent"]),
        "far unknown: Bonxai": percent(quality["far_unknown_percent"]),
        "Bonxai (s)": f"{result['insert_seconds']:.3f}",
        "MVOG / Bonxai speed": f"{ratios['readings_per_second_ratio']:.2f}x",
        "Bonxai held": megabytes(result["memory_bytes"]),
        "MVOG / Bonxai memory": f"{ratios['memory_ratio']:.3f}x",
    }


def state_agreement(agreement):
    """The % of the points in the same state in both maps (an agreement of mvog_bench's JSON)."""
    return percent(100.0 * agreement["fraction"]) if agreement["points"] else "-"


def every_reading_row(name, resolution, run):
    """MVOG's default insertion (one ray per end voxel) against every reading's walk, when the run
    has both (--backend every-reading): rays, time and memory ratios, and the agreement."""
    results = {b: by_resolution(run["results"], b).get(resolution)
               for b in ("mvog", "mvog_every_reading")}
    agreement = by_resolution(run.get("every_reading_agreement", [])).get(resolution)
    mv, every = results["mvog"], results["mvog_every_reading"]
    if not (mv and every and agreement):
        return None
    return [name, f"{resolution:g}", f"{mv['readings']:,}", f"{mv['rays_walked']:,}",
            f"{every['insert_seconds']:.3f}", f"{mv['insert_seconds']:.3f}",
            f"{every['insert_seconds'] / mv['insert_seconds']:.2f}x",
            f"{mv['memory_bytes'] / every['memory_bytes']:.3f}x",
            state_agreement(agreement["endpoints"]), state_agreement(agreement["along_rays"]),
            state_agreement(agreement["near_ends"])]


def file_name(path, prefix):
    return os.path.basename(path)[len(prefix):-len(".json")]


def threaded_runs(out):
    """benchmarks.sh's runs of one and two threads in turn (threadsN_roundR_FILE.json): MVOG's
    result at 0.05 m of every round, by file, then by thread count."""
    runs = {}
    for path in glob.glob(f"{out}/threads[12]_round*_*.json"):
        prefix, _, name = os.path.basename(path)[:-len(".json")].split("_", 2)
        result = by_resolution(load(path)["results"], "mvog")[0.05]
        runs.setdefault(name, {1: [], 2: []})[int(prefix[len("threads"):])].append(result)
    return {name: by_threads for name, by_threads in runs.items()
            if by_threads[1] and by_threads[2]}


def fastest(results):
    return min(results, key=lambda r: r["insert_seconds"])


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


AGAINST_OCTOMAP_COLUMNS = [
    "res (m)", "readings", "ends occupied: MVOG / OctoMap", "along free: MVOG / OctoMap",
    "far unknown: MVOG / OctoMap", "MVOG / OctoMap speed", "MVOG / walk time",
    "MVOG / OctoMap memory"]


def against_octomap_row(name, resolution, run):
    """One resolution of an mvog_bench run of all backends: each backend's quality, and MVOG's
    speed and memory as ratios (AGAINST_OCTOMAP_COLUMNS)."""
    mvog_quality, octomap_quality, results, comparison = by_backend(run)
    m, o = mvog_quality[resolution], octomap_quality[resolution]

    def both(key):
        return f"{percent(m[key])} / {percent(o[key])}"

    return [name, f"{resolution:g}", f"{results['mvog'][resolution]['readings']:,}",
            both("endpoints_occupied_percent"), both("along_rays_free_percent"),
            both("far_unknown_percent"),
            f"{comparison[resolution]['readings_per_second_ratio']:.1f}x",
            f"{results['walk'][resolution]['mvog_time_ratio']:.2f}x",
            f"{comparison[resolution]['memory_ratio']:.3f}x"]


def main(out):
    runs = {file_name(p, "all_"): load(p) for p in sorted(glob.glob(f"{out}/all_*.json"))}
    paper = {file_name(p, "paper_"): load(p) for p in glob.glob(f"{out}/paper_*.json")}
    threaded = threaded_runs(out)
    if not runs:
        sys.exit(f"benchmark_tables.py: no all_*.json in {out}")

    quality, speed, memory, threads, every_reading = [], [], [], [], []
    # Bonxai's columns when some run has them (mvog_bench built with MVOG_PEERS_DIR).
    with_bonxai = any(run.get("bonxai_comparison") for run in runs.values())
    for name, run in runs.items():
        mvog_quality, octomap_quality, results, comparison = by_backend(run)
        paper_quality = by_resolution(paper[name]["quality"], "mvog") if name in paper else {}
        table_one = by_resolution(run["table_one"])
        for resolution in sorted(mvog_quality, reverse=True):
            m, o = mvog_quality[resolution], octomap_quality[resolution]
            p = paper_quality.get(resolution)
            bonxai = bonxai_columns(run, resolution)
            quality.append([
                name, f"{resolution:g}",
                percent(m["endpoints_occupied_percent"]), percent(o["endpoints_occupied_percent"]),
                percent(p["endpoints_occupied_percent"]) if p else "-",
                percent(m["along_rays_free_percent"]), percent(o["along_rays_free_percent"]),
                percent(p["along_rays_free_percent"]) if p else "-",
                percent(m["far_unknown_percent"]), percent(o["far_unknown_percent"]),
            ] + ([bonxai[c] for c in BONXAI_QUALITY] if with_bonxai else []))
            mv, oc, walk = (results[b][resolution] for b in ("mvog", "octomap", "walk"))
            speed.append([
                name, f"{resolution:g}", f"{mv['readings']:,}",
                f"{mv['insert_seconds']:.3f}", f"{oc['insert_seconds']:.3f}",
                f"{walk['insert_seconds']:.3f}",
                f"{mv['readings_per_second'] / 1e6:.2f}",
                f"{comparison[resolution]['readings_per_second_ratio']:.1f}x",
                f"{walk['mvog_time_ratio']:.2f}x",
            ] + ([bonxai[c] for c in BONXAI_SPEED] if with_bonxai else []))
            every_reading.append(every_reading_row(name, resolution, run))
            memory.append([
                name, f"{resolution:g}", megabytes(mv["memory_bytes"]),
                megabytes(oc["memory_bytes"]), f"{comparison[resolution]['memory_ratio']:.3f}x",
                megabytes(table_one[resolution]["mvog_bytes"]),
                megabytes(table_one[resolution]["octomap_bytes"]),
                megabytes(mv["file_bytes"]), megabytes(oc["full_file_bytes"]),
            ] + ([bonxai[c] for c in BONXAI_MEMORY] if with_bonxai else []))
        if name in threaded:
            one, two = (fastest(threaded[name][t]) for t in (1, 2))
            checksums = {r["map_checksum"] for t in (1, 2) for r in threaded[name][t]}
            threads.append([
                name, f"{one['insert_seconds']:.3f}", f"{two['insert_seconds']:.3f}",
                f"{one['insert_seconds'] / two['insert_seconds']:.2f}x",
                "yes" if len(checksums) == 1 else "NO",
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
                 "along free: MVOG", "OctoMap", "paper model", "far unknown: MVOG", "OctoMap"] +
                (BONXAI_QUALITY if with_bonxai else []), quality))
    print("\n### Speed (one thread)\n")
    print(table(["file", "res (m)", "readings", "MVOG (s)", "OctoMap (s)", "walk (s)",
                 "MVOG M readings/s", "MVOG / OctoMap speed", "MVOG / walk time"] +
                (BONXAI_SPEED if with_bonxai else []), speed))
    # The synthetic sensors too (scenes built in code: sensors none of the recordings has).
    for path in sorted(glob.glob(f"{out}/synthetic_*.json")):
        run = load(path)
        for resolution in sorted(by_resolution(run["quality"], "mvog"), reverse=True):
            every_reading.append(every_reading_row(file_name(path, "synthetic_"), resolution, run))
    every_reading = [r for r in every_reading if r]
    if every_reading:
        print("\n### One ray per end voxel against every reading's ray (MVOG, one thread)\n")
        print(table(["file", "res (m)", "readings", "rays walked", "every reading (s)",
                     "one per end voxel (s)", "speed-up", "memory", "same state: ends",
                     "along rays", "within 2 cells of the ends"], every_reading))
    print("\n### Memory (MB)\n")
    print(table(["file", "res (m)", "MVOG held", "OctoMap held (pruned)", "MVOG / OctoMap",
                 "Table I: MVOG", "Table I: OctoMap", "MVOG file", "OctoMap .ot file"] +
                (BONXAI_MEMORY if with_bonxai else []), memory))
    print("\n### Threads (0.05 m)\n")
    print(table(["file", "1 thread (s)", "2 threads (s)", "speed-up", "same map"], threads))
    other_resolutions = {file_name(p, "resolutions_"): load(p)
                         for p in glob.glob(f"{out}/resolutions_*.json")}
    if other_resolutions:
        rows = [(name, resolution, source)
                for name, run in runs.items()
                for source in [run, other_resolutions.get(name)] if source is not None
                for resolution in by_resolution(source["quality"], "mvog")]
        rows.sort(key=lambda r: (r[0], -r[1]))
        print("\n### Every file at 0.1, 0.05 and 0.02 m (one thread)\n")
        print(table(["file"] + AGAINST_OCTOMAP_COLUMNS,
                    [against_octomap_row(name, resolution, source)
                     for name, resolution, source in rows]))
    synthetic_rows = [against_octomap_row(file_name(path, "synthetic_"), resolution, run)
                      for path in sorted(glob.glob(f"{out}/synthetic_*.json"))
                      for run in [load(path)]
                      for resolution in sorted(by_resolution(run["quality"], "mvog"),
                                               reverse=True)]
    if synthetic_rows:
        print("\n### Sensors none of the recordings has (mvog_bench --input synthetic:NAME, "
              "one insertion)\n")
        print(table(["sensor"] + AGAINST_OCTOMAP_COLUMNS, synthetic_rows))

    def quality_at(run, resolution=0.05):
        q = by_resolution(run["quality"], "mvog").get(resolution)
        return (f"{percent(q['endpoints_occupied_percent'])} / "
                f"{percent(q['along_rays_free_percent'])}") if q else "-"

    rules = {file_name(p, "rule_"): load(p) for p in glob.glob(f"{out}/rule_*.json")}
    rule_columns = [("clip_off", "clip free space at hits: off"),
                    ("per_reading", "mass counting: per reading"),
                    ("split_off", "split free space at obstacles: off"),
                    ("threshold_0.5", "threshold 0.5")]
    rule_rows = [[name, quality_at(run)] +
                 [quality_at(rules[f"{key}_{name}"]) if f"{key}_{name}" in rules else "-"
                  for key, _ in rule_columns] +
                 [quality_at(paper[name]) if name in paper else "-"]
                 for name, run in runs.items()]
    if rules:
        print("\n### The rules one at a time (MVOG, 0.05 m: ends occupied / along rays free, %)\n")
        print(table(["file", "defaults"] + [title for _, title in rule_columns] + ["paper model"],
                    rule_rows))
    lengths = ["1", "2", "4", "inf"]
    out_of_range_rows = [[name, quality_at(runs[name])] +
                         [quality_at(rules[f"out_of_range_{n}_{name}"]) for n in lengths]
                         for name in runs if f"out_of_range_2_{name}" in rules]
    if out_of_range_rows:
        print("\n### Free length of out-of-range readings (MVOG, 0.05 m: ends occupied / along "
              "rays free, %)\n")
        print(table(["file", "disregarded"] + [f"{n} m" if n != "inf" else "unbounded"
                                              for n in lengths], out_of_range_rows))

    table_one_rows = []
    for path in sorted(glob.glob(f"{out}/table_one_*.json")):
        name = file_name(path, "table_one_")
        for t in sorted(load(path)["table_one"], key=lambda t: -t["resolution"]):
            table_one_rows.append([
                name, f"{t['resolution']:g}", megabytes(t["point_cloud_bytes"]),
                megabytes(t["voxel_grid_bytes"]), megabytes(t["octomap_bytes"]),
                megabytes(t["mvog_bytes"]), f"{t['mvog_bytes'] / t['octomap_bytes']:.2f}"])
    if table_one_rows:
        print("\n### Table I's accounting (MB: 12 bytes a point; 4 a voxel of the smallest grid "
              "holding every ray; OctoMap's pruned tree; 12 bytes a volume + 8 a cell)\n")
        print(table(["data", "res (m)", "point cloud", "voxel grid", "OctoMap", "MVOG",
                     "MVOG / OctoMap"], table_one_rows))

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
