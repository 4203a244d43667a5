#!/usr/bin/python3
"""Draws the benchmarks' figures from their CSVs, each PNG beside its CSV.

    scripts/plot-figures.py [CSV ...]

With no argument: every figure of docs/figures/ (convergence/*.csv and
lut_vs_path.csv).  A CSV's columns say which figure it is, so the output of a
fresh run can be drawn too:

    skyfarm-worker bench convergence --out /tmp/conv && scripts/plot-figures.py /tmp/conv/*.csv

  convergence   (skyfarm-worker bench convergence: elapsed_s,
                samples_per_pixel, true_relative_rms, estimated_relative_rms)
                error against render time, log-log: the true error against the
                converged reference, the render's own estimate, and a line of
                slope -1/2 (a sound Monte Carlo estimator) through the first
                true error.
  lut_vs_path   (skyfarm-worker bench lut-vs-path: altitude_m,
                sun_zenith_deg, luminance_rel_rms, reference_est_rel_rms, ...)
                the LUT sky's luminance error against sun zenith, one line per
                observer altitude, and dashed the path-traced references' own
                estimated error (errors below it are not resolved).

Needs matplotlib (Debian: python3-matplotlib); the tests do not run this.
"""
import csv
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
FIGURES = ROOT / "docs" / "figures"

# The convergence scenes (worker/bench_convergence.cpp), as titles.
SCENES = {
    "noon": "sun at 30° zenith, ground",
    "sun85": "sun at 85° zenith, ground",
    "sunset": "sunset, sun at 90° zenith",
    "twilight96": "twilight, sun at 96° zenith",
    "orbit400km": "view from 400 km, sun at 45° zenith",
    "haze": "haze (AOD 0.5 at 550 nm), sun at 40° zenith",
}
ALTITUDES = {0.0: ("ground", "tab:red"), 10000.0: ("10 km", "tab:green"), 100000.0: ("100 km", "tab:blue")}

SIZE = (6.4, 4.2)  # inches; at DPI 100: 640 x 420 pixels
DPI = 100
# No software version or date in the PNG: the same CSV draws the same file.
METADATA = {"Software": None}


def percent(value, _position):
    return f"{value * 100:g} %"


def seconds(value, _position):
    return f"{value:g}"


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def plot_convergence(path, rows):
    t = [float(r["elapsed_s"]) for r in rows]
    spp = [int(r["samples_per_pixel"]) for r in rows]
    truth = [float(r["true_relative_rms"]) for r in rows]
    estimate = [float(r["estimated_relative_rms"]) for r in rows]
    fig, ax = plt.subplots(figsize=SIZE, dpi=DPI)
    ax.loglog(t, truth, "-o", color="tab:red", markersize=3, label="true error (against the reference)")
    ax.loglog(t, estimate, "-s", color="tab:blue", markersize=3, label="estimated error (the render's own)")
    ax.loglog([t[0], t[-1]], [truth[0], truth[0] * (t[-1] / t[0]) ** -0.5], "--", color="0.45",
              label="slope −1/2")
    ax.xaxis.set_major_formatter(FuncFormatter(seconds))
    ax.xaxis.set_minor_locator(LogLocator(subs=(2, 5)))
    ax.xaxis.set_minor_formatter(FuncFormatter(seconds))
    ax.set_xlabel("render time (s), one point per pass of 16 samples per pixel")
    ax.set_ylabel("relative RMS error of luminance")
    ax.yaxis.set_major_formatter(FuncFormatter(percent))
    ax.yaxis.set_minor_locator(LogLocator(subs=(2, 3, 5)))
    ax.yaxis.set_minor_formatter(FuncFormatter(percent))
    ax.grid(True, which="major", color="0.85")
    ax.grid(True, which="minor", color="0.93")
    scene = SCENES.get(path.stem, path.stem)
    ax.set_title(f"Error against render time: {scene}\n64×32 equirectangular, {spp[0]} to {spp[-1]} spp",
                 fontsize=10)
    ax.legend(fontsize=8)
    return fig


def plot_lut_vs_path(path, rows):
    fig, ax = plt.subplots(figsize=SIZE, dpi=DPI)
    by_altitude = {}
    for r in rows:
        by_altitude.setdefault(float(r["altitude_m"]), []).append(r)
    handles = []
    for altitude, group in sorted(by_altitude.items()):
        name, colour = ALTITUDES.get(altitude, (f"{altitude:g} m", None))
        zenith = [float(r["sun_zenith_deg"]) for r in group]
        (line,) = ax.semilogy(zenith, [float(r["luminance_rel_rms"]) for r in group], "-o", color=colour,
                              markersize=3, label=f"observer on the {name}" if altitude == 0 else f"observer at {name}")
        ax.semilogy(zenith, [float(r["reference_est_rel_rms"]) for r in group], "--", color=line.get_color(),
                    alpha=0.6, linewidth=1)
        handles.append(line)
    handles += [Line2D([], [], color="0.3", linestyle="-", label="LUT against the reference"),
                Line2D([], [], color="0.3", linestyle="--", linewidth=1, alpha=0.6,
                       label="the reference's own estimated error")]
    ax.set_xlabel("sun zenith angle (°); points: 0, 30, 60, 80, 85, 90, 93, 96")
    ax.set_ylabel("relative RMS error of luminance")
    ax.set_xlim(-2, 100)
    ax.set_xticks(range(0, 101, 10))
    ax.set_ylim(1e-3, 1.0)
    ax.yaxis.set_major_formatter(FuncFormatter(percent))
    ax.grid(True, which="major", color="0.85")
    ax.set_title("LUT sky against path-traced references\n36×18 equirectangular, 8 wavelength batches, "
                 "sun disk left out", fontsize=10)
    ax.legend(handles=handles, fontsize=8, loc="upper left")
    return fig


def figure_for(path):
    rows = read(path)
    if not rows:
        raise SystemExit(f"plot-figures: {path}: no rows")
    columns = set(rows[0])
    if {"elapsed_s", "true_relative_rms", "estimated_relative_rms"} <= columns:
        return plot_convergence(path, rows)
    if {"altitude_m", "sun_zenith_deg", "luminance_rel_rms", "reference_est_rel_rms"} <= columns:
        return plot_lut_vs_path(path, rows)
    raise SystemExit(f"plot-figures: {path}: not a figure's CSV (columns {', '.join(rows[0])})")


def main(args):
    paths = [pathlib.Path(a) for a in args] or sorted(FIGURES.glob("convergence/*.csv")) + [
        FIGURES / "lut_vs_path.csv"]
    for path in paths:
        fig = figure_for(path)
        fig.tight_layout()
        out = path.with_suffix(".png")
        fig.savefig(out, metadata=METADATA)
        plt.close(fig)
        print(out)


if __name__ == "__main__":
    main(sys.argv[1:])
