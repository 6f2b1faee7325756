#!/usr/bin/env python3
"""An example of the Python module mvog: loads a saved map and writes a cross-section and a top
view as PNG images with matplotlib (no ROS needed beyond a sourced workspace).

  python3 scripts/python_map_views.py [MAP] [--z Z] [--z-min ZMIN] [--z-max ZMAX] [--out PREFIX]

MAP defaults to the map scripts/demo.sh saves (out/demo/demo.mvog); mvog_synthetic_demo's
synthetic_room.mvog, or any map saved by the server's ~save_map, works alike. Writes
PREFIX_cross_section.png (eq. 9 at height Z, m: the probability of occupancy, grey where unknown)
and PREFIX_top_view.png (occupied, free and unknown over the band [ZMIN, ZMAX], m), both in the
map frame with +x right and +y up. PREFIX defaults to MAP without its extension.
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402 (after choosing the backend)
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

import mvog  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def save_cross_section(world, z, path):
    section = world.cross_section(z)
    probabilities = np.ma.masked_invalid(section.values)  # NaN: unknown
    colours = plt.get_cmap("RdYlGn_r").copy()
    colours.set_bad("lightgrey")
    figure, axes = plt.subplots(figsize=(8, 8))
    image = axes.imshow(probabilities, origin="lower", extent=section.extent, cmap=colours,
                        vmin=0.0, vmax=1.0, interpolation="nearest")
    figure.colorbar(image, ax=axes, shrink=0.8, label="probability of occupancy (eq. 9)")
    axes.set_title("cross-section at z = %.2f m (grey: unknown)" % z)
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    figure.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(figure)


def save_top_view(world, z_min, z_max, path):
    top = world.projection(z_min, z_max)
    # uint8 OccupancyState values: 0 unknown, 1 free, 2 occupied.
    colours = ListedColormap(["lightgrey", "white", "black"])
    figure, axes = plt.subplots(figsize=(8, 8))
    axes.imshow(top.values, origin="lower", extent=top.extent, cmap=colours, vmin=0, vmax=2,
                interpolation="nearest")
    axes.set_title("top view, z in [%g, %g] m (black occupied, white free, grey unknown)"
                   % (z_min, z_max))
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    figure.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(figure)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("map", nargs="?", default=str(REPO / "out" / "demo" / "demo.mvog"))
    parser.add_argument("--z", type=float, default=0.5, help="cross-section height (m)")
    parser.add_argument("--z-min", type=float, default=0.1, help="top view band (m), above the floor")
    parser.add_argument("--z-max", type=float, default=2.0, help="top view band (m)")
    parser.add_argument("--out", help="prefix of the images (default: MAP without .mvog)")
    args = parser.parse_args()
    world = mvog.load_map(Path(args.map))
    if world.empty:
        parser.error("%s holds no volume" % args.map)
    prefix = args.out or str(Path(args.map).with_suffix(""))
    save_cross_section(world, args.z, prefix + "_cross_section.png")
    save_top_view(world, args.z_min, args.z_max, prefix + "_top_view.png")
    usage = world.memory_usage()
    print("%s: %d cells, %d volumes, resolution %g m; wrote %s_cross_section.png and "
          "%s_top_view.png" % (args.map, usage.cells_with_volumes,
                               usage.positive_volumes + usage.negative_volumes,
                               world.resolution, prefix, prefix))


if __name__ == "__main__":
    main()
