#!/usr/bin/env python3
"""A driver whose model has a closed form and writes its own gradients.

Usage: closed_form.py INPUT RESULTS FORMAT
  INPUT    lines "name = value" (a, b)
  RESULTS  the results file, with gradients with respect to a and b
  FORMAT   "json": f = (a - 2)^2 + (b - 1)^2, the series y(t) = a t + b t^2
           on t = 0, 0.25, ..., 1, and their gradients;
           "dakota": f and g = a + b, then one gradient line each, in the
           order a, b (Dakota's results file).

Numbers are written with repr, the shortest text that reads back to the
same double, so the same input gives the same bytes.
"""
import json
import sys


def read_input(path):
    values = {}
    with open(path) as f:
        for line in f:
            if "=" in line:
                name, value = line.split("=", 1)
                values[name.strip()] = float(value)
    return values["a"], values["b"]


def main():
    input_path, results_path, results_format = sys.argv[1:4]
    a, b = read_input(input_path)
    f = (a - 2.0) ** 2 + (b - 1.0) ** 2
    df = {"a": 2.0 * (a - 2.0), "b": 2.0 * (b - 1.0)}
    with open(results_path, "w") as out:
        if results_format == "json":
            times = [0.0, 0.25, 0.5, 0.75, 1.0]
            out.write(json.dumps({
                "values": {"f": f},
                "series": {"y": [a * t + b * t * t for t in times]},
                "time": times,
                "gradients": {
                    "values": {"f": df},
                    "series": {"y": {"a": times, "b": [t * t for t in times]}},
                },
            }))
        else:
            out.write("%r f\n%r g\n[ %r %r ]\n[ 1.0 1.0 ]\n" % (f, a + b, df["a"], df["b"]))


main()
