"""Reading a series file: what `mbopt-worker eval --series-out FILE` writes,
a binary mbopt.v1.AnalysisSeries (proto/mbopt/v1/series.proto). The values
are plain repeated doubles in SI units, no packing of mbopt's own
(common/packed_doubles packs only what workers send the server), so the
protobuf library decodes them exactly: each value is the double the worker
computed, bit for bit.
"""

import os

from mbopt.errors import BadInput
from mbopt.v1 import series_pb2

try:
    import numpy
except ImportError:  # numpy is optional: plain lists then
    numpy = None


class Signal:
    """One output (per load case, "<case>.<output>") or response, with one
    or more series: `labels[i]` names `series[i]` (a bending stress has one
    per node; a scalar response's series has one value)."""

    def __init__(self, name, labels, series):
        self.name = name
        self.labels = labels
        self.series = series

    def values(self, label=None):
        """The series of that label; without one, the only series."""
        if label is None:
            if len(self.series) != 1:
                raise KeyError(f"{self.name} has {len(self.series)} series ({', '.join(self.labels)}): name a label")
            return self.series[0]
        try:
            return self.series[self.labels.index(label)]
        except ValueError:
            raise KeyError(f"{self.name} has no series {label!r} (labels: {', '.join(self.labels)})") from None

    def __repr__(self):
        return f"Signal({self.name!r}, labels={self.labels!r})"


class AnalysisSeries:
    """`times_s`, the signals by name (in the file's order: outputs case by
    case, then responses), and `failure` (empty when the analysis
    succeeded)."""

    def __init__(self, times_s, signals, failure):
        self.times_s = times_s
        self.signals = signals
        self.failure = failure

    def __getitem__(self, name):
        return self.signals[name]

    def names(self):
        return list(self.signals)


def read_series(path, use_numpy=True):
    """The series file at `path`: values as numpy float64 arrays when numpy is
    installed and `use_numpy`, else as lists of floats."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise BadInput(f"{path}: cannot open file: {e.strerror}") from None
    message = series_pb2.AnalysisSeries()
    try:
        message.ParseFromString(data)
    except Exception as e:  # the library's DecodeError; its module varies by backend
        raise BadInput(f"{path}: not a series file (binary mbopt.v1.AnalysisSeries): {e}") from None
    as_array = (lambda v: numpy.array(v, dtype=numpy.float64)) if (use_numpy and numpy is not None) else list
    signals = {}
    for s in message.signals:
        signals[s.name] = Signal(s.name, list(s.labels), [as_array(v.values_si) for v in s.series])
    return AnalysisSeries(as_array(message.times_s), signals, message.failure)
