#!/usr/bin/env python3
"""Work-precision diagrams (SVG) from bench_multibody_workprec's table.

One diagram per mechanism: each code's error against its own tight
reference (x, rad) and the median CPU time of one integration (y, s), both
on log scales; one curve per integrator, points labelled with their
tolerance's exponent, and Simbody's fastest time divided by three dashed
(the target of issue 30: mbopt's curve below it).

    python3 bench/multibody/workprec_svg.py docs/svg/workprec_multibody.csv docs/svg

writes docs/svg/workprec_<mechanism>.svg. Standard library only.
"""

import csv
import math
import sys
from collections import defaultdict

TITLES = {
    "ten_body_chain": "Ten-body chain (five rockers, four couplers, a pendulum), 2 s",
    "rod_chain": "Closed chain of ten rods (8 degrees of freedom), 2 s",
    "andrews": "Andrews' squeezing mechanism, 0.03 s",
}
STYLES = {  # (code, integrator) -> colour, label
    ("mbopt", "idas"): ("#c0392b", "mbopt (IDAS)"),
    ("mbopt", "erk"): ("#27ae60", "mbopt (explicit RK 6(5), projected)"),
    ("simbody", "rkm"): ("#2c3e50", "Simbody (Runge-Kutta-Merson, RKM)"),
    ("simbody", "cpodes"): ("#7f8c8d", "Simbody (CPodes BDF)"),
}
WIDTH, HEIGHT = 640, 440
LEFT, RIGHT, TOP, BOTTOM = 70, 20, 40, 90


def read_runs(path):
    """Rows of successful runs by mechanism, then by (code, integrator)."""
    runs = defaultdict(lambda: defaultdict(list))
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            error, cpu = float(row["error_rad"]), float(row["cpu_s"])
            if row["failure"] or not (error > 0 and cpu > 0):
                continue
            runs[row["mechanism"]][(row["code"], row["integrator"])].append(
                (float(row["tolerance"]), error, cpu))
    return runs


def decades(lo, hi):
    return range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1)


def diagram(mechanism, curves):
    points = [p for c in curves.values() for p in c]
    simbody = [p for key, c in curves.items() if key[0] == "simbody" for p in c]
    errors = [p[1] for p in points]
    times = [p[2] for p in points] + [p[2] / 3 for p in simbody]
    x_dec, y_dec = decades(min(errors), max(errors)), decades(min(times), max(times))
    x0, x1, y0, y1 = x_dec[0], x_dec[-1], y_dec[0], y_dec[-1]
    plot_w, plot_h = WIDTH - LEFT - RIGHT, HEIGHT - TOP - BOTTOM

    def sx(error):  # larger errors to the left: precision grows to the right
        return LEFT + plot_w * (x1 - math.log10(error)) / (x1 - x0)

    def sy(seconds):
        return TOP + plot_h * (y1 - math.log10(seconds)) / (y1 - y0)

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" '
           f'font-family="sans-serif" font-size="11">',
           f'<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>',
           f'<text x="{WIDTH / 2}" y="20" text-anchor="middle" font-size="13">'
           f'{TITLES.get(mechanism, mechanism)}</text>']
    for d in x_dec:
        x = sx(10.0 ** d)
        out.append(f'<line x1="{x:.1f}" y1="{TOP}" x2="{x:.1f}" y2="{TOP + plot_h}" stroke="#ddd"/>')
        out.append(f'<text x="{x:.1f}" y="{TOP + plot_h + 15}" text-anchor="middle">1e{d}</text>')
    for d in y_dec:
        y = sy(10.0 ** d)
        out.append(f'<line x1="{LEFT}" y1="{y:.1f}" x2="{LEFT + plot_w}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{LEFT - 6}" y="{y + 4:.1f}" text-anchor="end">1e{d}</text>')
    out.append(f'<rect x="{LEFT}" y="{TOP}" width="{plot_w}" height="{plot_h}" fill="none" stroke="black"/>')
    out.append(f'<text x="{LEFT + plot_w / 2}" y="{TOP + plot_h + 32}" text-anchor="middle">'
               'largest angle error against the code\'s own tight reference (rad)</text>')
    out.append(f'<text transform="translate(16,{TOP + plot_h / 2}) rotate(-90)" text-anchor="middle">'
               'CPU time per integration, median (s)</text>')

    def polyline(pts, colour, dashed=False):
        path = " ".join(f"{sx(e):.1f},{sy(t):.1f}" for e, t in pts)
        dash = ' stroke-dasharray="5,4"' if dashed else ""
        return f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="1.5"{dash}/>'

    legend = []
    for key, (colour, label) in STYLES.items():
        if key not in curves:
            continue
        pts = sorted(curves[key], reverse=True)  # loosest tolerance first
        out.append(polyline([(e, t) for _, e, t in pts], colour))
        for tol, e, t in pts:
            out.append(f'<circle cx="{sx(e):.1f}" cy="{sy(t):.1f}" r="3" fill="{colour}"/>')
            if key[0] == "mbopt":
                out.append(f'<text x="{sx(e) + 4:.1f}" y="{sy(t) + 13:.1f}" fill="{colour}" font-size="9">'
                           f'{round(math.log10(tol))}</text>')
        legend.append((colour, label, False))
    if ("simbody", "rkm") in curves:
        pts = sorted(curves[("simbody", "rkm")], reverse=True)
        out.append(polyline([(e, t / 3) for _, e, t in pts], STYLES[("simbody", "rkm")][0], dashed=True))
        legend.append((STYLES[("simbody", "rkm")][0], "3x target: Simbody RKM time / 3", True))
    for i, (colour, label, dashed) in enumerate(legend):
        y = TOP + plot_h + 50 + 13 * (i % 3)
        x = LEFT + (i // 3) * 280
        dash = ' stroke-dasharray="5,4"' if dashed else ""
        out.append(f'<line x1="{x}" y1="{y - 4}" x2="{x + 20}" y2="{y - 4}" stroke="{colour}" '
                   f'stroke-width="1.5"{dash}/>')
        out.append(f'<text x="{x + 25}" y="{y}">{label}</text>')
    out.append(f'<text x="{LEFT + plot_w}" y="{TOP - 4}" text-anchor="end" font-size="9">'
               'numbers: log10 of mbopt\'s rtol</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: workprec_svg.py TABLE.csv OUTPUT_DIR")
    runs = read_runs(sys.argv[1])
    if not runs:
        sys.exit(f"{sys.argv[1]}: no successful runs")
    for mechanism, curves in runs.items():
        path = f"{sys.argv[2]}/workprec_{mechanism}.svg"
        with open(path, "w") as f:
            f.write(diagram(mechanism, curves))
        print(path)


if __name__ == "__main__":
    main()
