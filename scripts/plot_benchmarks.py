#!/usr/bin/python3
"""Draws the benchmark figures of docs/benchmarks.md as plots in docs/images/.

    scripts/plot_benchmarks.py [--tables docs/benchmarks.md] [--out docs/images] [--check]

Reads the result tables in docs/benchmarks.md — the published figures of scripts/bench.sh's runs,
one table per program, found by their header cells — so each plot always shows the numbers of the
table beside it: after a new bench run, update the tables, run this, commit both. Writes:

    bvh-scaling.png        ns per ray against the number of spheres: BVH, brute force, Embree
    ray-throughput.png     Mrays/s of glint and Embree per ray set, 1 and 2 threads
    renderer-times.png     whole-render seconds of glint, Tachyon and POV-Ray
    adaptive-sampling.png  RMS error against samples per pixel, fixed and adaptive

Needs python3-matplotlib (scripts/setup.sh bench installs it). The PNGs carry no date or version,
so the same tables give the same files. --check draws nothing and needs no matplotlib: it finds
each plot's table and checks that its cells read as the plot reads them (the ctest
benchmark_tables runs it, so that a table added to benchmarks.md cannot hide one of these).
"""
import argparse
import os
import re
import sys

matplotlib = None  # imported by load_matplotlib: --check runs without it
plt = None


def load_matplotlib():
    global matplotlib, plt
    import matplotlib as mpl
    import matplotlib.ticker  # noqa: F401
    mpl.use("Agg")
    import matplotlib.pyplot as pyplot
    matplotlib, plt = mpl, pyplot

COLORS = {"glint": "#d9622b", "Embree": "#4a7bb7", "Tachyon": "#5a9e5a", "POV-Ray": "#8e6bb5",
          "brute force": "#999999", "fixed": "#4a7bb7", "adaptive": "#d9622b"}
PNG_METADATA = {"Software": None}  # no matplotlib version in the file


def tables(markdown):
    """Every pipe table as (header cells, rows of cells), bold markers removed."""
    found, current = [], None
    for line in markdown.splitlines():
        if line.startswith("|"):
            cells = [c.strip().replace("**", "") for c in line.strip().strip("|").split("|")]
            if current is None:
                current = (cells, [])
                found.append(current)
            elif not all(re.fullmatch(r":?-+:?", c) for c in cells):
                current[1].append(cells)
        else:
            current = None
    return found


def table_starting(all_tables, first_cell):
    for header, rows in all_tables:
        if header[0].startswith(first_cell):
            return header, rows
    sys.exit("plot_benchmarks: no table whose first header cell starts with %r" % first_cell)


def number(text):
    match = re.search(r"[-+]?\d+(\.\d+)?", text.replace(",", ""))
    return float(match.group(0)) if match else None


def pair(text):
    """'5.10 / 11.31' -> (5.10, 11.31)"""
    return tuple(number(part) for part in text.split("/"))


def count(label):
    """'1k' -> 1000, '1M' -> 1e6"""
    scale = {"k": 1e3, "M": 1e6}.get(label[-1], 1)
    return float(label.rstrip("kM")) * scale


def save(figure, path):
    figure.tight_layout()
    figure.savefig(path, dpi=110, metadata=PNG_METADATA)
    plt.close(figure)
    print("wrote", path)


def plot_bvh_scaling(all_tables, path):
    header, rows = table_starting(all_tables, "spheres (1 thread, ns per ray")
    sizes = [count(h) for h in header[1:]]
    figure, axes = plt.subplots(figsize=(6.4, 4))
    for row in rows:
        name = row[0].replace("glint ", "glint ").strip()
        points = [(n, number(v)) for n, v in zip(sizes, row[1:]) if number(v) is not None]
        key = "brute force" if "brute" in name else ("Embree" if "Embree" in name else "glint")
        style = "--" if key == "brute force" else "-"
        axes.plot(*zip(*points), style, marker="o", color=COLORS[key], label=name)
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("spheres in the scene")
    axes.set_ylabel("ns per ray (1 thread)")
    axes.set_title("BVH scaling: time per ray against scene size")
    axes.grid(True, which="major", alpha=0.3)
    axes.legend()
    save(figure, path)


def plot_ray_throughput(all_tables, path):
    header, rows = table_starting(all_tables, "ray throughput")
    labels = [row[0] for row in rows]
    figure, panels = plt.subplots(1, 2, figsize=(10, 5.2), sharey=True)
    for panel, threads, index in ((panels[0], "1 thread", 0), (panels[1], "2 threads", 1)):
        positions = range(len(rows))
        glint = [pair(row[1])[index] for row in rows]
        embree = [pair(row[2])[index] for row in rows]
        # The y axis is inverted below: glint's bar sits above Embree's, as in the legend.
        panel.barh([p - 0.2 for p in positions], glint, 0.4, color=COLORS["glint"], label="glint")
        panel.barh([p + 0.2 for p in positions], embree, 0.4, color=COLORS["Embree"], label="Embree")
        panel.set_title(threads)
        panel.set_xlabel("Mrays/s")
        panel.grid(True, axis="x", alpha=0.3)
    panels[0].set_yticks(range(len(rows)), labels)
    panels[0].invert_yaxis()
    panels[1].legend(loc="lower right")
    figure.suptitle("Ray throughput: glint and Embree 3 on the same rays")
    save(figure, path)


def plot_renderer_times(all_tables, path):
    header, rows = table_starting(all_tables, "whole render, seconds")
    renderers = header[1:4]
    figure, axes = plt.subplots(figsize=(8, 4.4))
    width = 0.27
    for i, name in enumerate(renderers):
        values = [number(row[1 + i]) for row in rows]
        axes.bar([p + (i - 1) * width for p in range(len(rows))], values, width,
                 color=COLORS[name], label=name)
    axes.set_xticks(range(len(rows)), [row[0].replace(", ", "\n", 1) for row in rows], fontsize=8)
    axes.set_ylabel("seconds, whole process (median of 3)")
    axes.set_title("Whole renders: glint, Tachyon and POV-Ray (1024×768)")
    axes.grid(True, axis="y", alpha=0.3)
    axes.legend()
    save(figure, path)


def plot_adaptive(all_tables, path):
    header, rows = table_starting(all_tables, "320×180")
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    for row in rows:
        if row[0].startswith("fixed"):
            spp, error = pair(row[1]), pair(row[2])
            axes.plot(spp, error, "-o", color=COLORS["fixed"], label="fixed sampling")
    adaptive = [(number(row[1]), number(row[2]), row[0].replace("adaptive ", ""))
                for row in rows if row[0].startswith("adaptive")]
    axes.plot([a[0] for a in adaptive], [a[1] for a in adaptive], "D", color=COLORS["adaptive"],
              label="adaptive sampling")
    for spp, error, name in adaptive:
        axes.annotate(name, (spp, error), textcoords="offset points", xytext=(6, 4), fontsize=8)
    axes.set_xscale("log", base=2)
    axes.set_yscale("log")
    axes.set_xticks([4, 8, 16, 32, 64], ["4", "8", "16", "32", "64"])
    # Plain decimals on the error axis (matplotlib's log axis would label only some ticks, as
    # "6×10^-3"), the same way the table writes them.
    ticks = [0.002, 0.003, 0.004, 0.005, 0.006, 0.008, 0.010]
    axes.yaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    axes.set_yticks(ticks, ["%.3f" % t for t in ticks])
    axes.set_xlabel("samples per pixel spent (average)")
    axes.set_ylabel("RMS error against a 256-spp reference")
    axes.set_title("Adaptive against fixed sampling (showcase, 320×180)")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend()
    save(figure, path)


def check_tables(all_tables):
    """The problems found in the tables the plots read, as messages (none: all readable)."""
    problems = []
    header, rows = table_starting(all_tables, "spheres (1 thread, ns per ray")
    for label in header[1:]:
        if not re.fullmatch(r"\d+[kM]?", label):
            problems.append("BVH scaling: column %r is not a sphere count" % label)
    if not rows:
        problems.append("BVH scaling: no rows")
    header, rows = table_starting(all_tables, "ray throughput")
    for row in rows:
        if len(row) < 3:
            problems.append("ray throughput: row %r has no glint and Embree columns" % row[0])
        for cell in row[1:3]:
            values = pair(cell)
            if len(values) != 2 or None in values:
                problems.append("ray throughput: %r is not 'N / N' in row %r" % (cell, row[0]))
    header, rows = table_starting(all_tables, "whole render, seconds")
    for name in header[1:4]:
        if name not in COLORS:
            problems.append("whole renders: column %r is not a renderer (the first table whose "
                            "first cell starts 'whole render, seconds' is the plotted one)" % name)
    for row in rows:
        if any(number(cell) is None for cell in row[1:4] if cell != "-"):
            problems.append("whole renders: row %r has a cell that is no number" % row[0])
    header, rows = table_starting(all_tables, "320×180")
    if not any(row[0].startswith("fixed") for row in rows) or \
            not any(row[0].startswith("adaptive") for row in rows):
        problems.append("adaptive sampling: no 'fixed' or no 'adaptive' rows")
    return problems


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tables", default=os.path.join(root, "docs", "benchmarks.md"))
    parser.add_argument("--out", default=os.path.join(root, "docs", "images"))
    parser.add_argument("--check", action="store_true",
                        help="only check that the plotted tables read; draw nothing")
    args = parser.parse_args()
    all_tables = tables(open(args.tables, encoding="utf-8").read())
    problems = check_tables(all_tables)
    for problem in problems:
        print("plot_benchmarks: %s: %s" % (args.tables, problem), file=sys.stderr)
    if problems:
        sys.exit(1)
    if args.check:
        print("plot_benchmarks: the plotted tables of %s read" % args.tables)
        return
    load_matplotlib()
    os.makedirs(args.out, exist_ok=True)
    plt.rcParams.update({"font.size": 9, "svg.hashsalt": "glint"})
    plot_bvh_scaling(all_tables, os.path.join(args.out, "bvh-scaling.png"))
    plot_ray_throughput(all_tables, os.path.join(args.out, "ray-throughput.png"))
    plot_renderer_times(all_tables, os.path.join(args.out, "renderer-times.png"))
    plot_adaptive(all_tables, os.path.join(args.out, "adaptive-sampling.png"))


if __name__ == "__main__":
    main()
