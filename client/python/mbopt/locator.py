"""Where each field of a text-format study or scene file is: line and
column (1-based) of its name, keyed by its path as mbopt's messages write
it ("variables[0].upper", "objective"), so that a message the server gives
for a submitted study can name the line as `mbopt validate` does
(spec/io/locator.cc). A repeated field without an index is where its first
element is; a field the file does not set is where the message holding it
is, and a top-level one has no line.
"""

import re

_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<comment>\#[^\n]*)
  | (?P<string>"(?:[^"\\\n]|\\.)*"|'(?:[^'\\\n]|\\.)*')
  | (?P<word>[-+]?(?:0[xX][0-9A-Fa-f]+|[0-9.]+(?:[eE][-+]?[0-9]+)?[fF]?|[A-Za-z_][A-Za-z0-9_.]*))
  | (?P<punct>.)
""", re.VERBOSE)


def tokens(text):
    """(kind, text, line, column) of every token; line and column 1-based."""
    line, line_start = 1, 0
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        if kind not in ("space", "comment"):
            yield kind, m.group(), line, m.start() - line_start + 1
        newlines = m.group().count("\n")
        if newlines:
            line += newlines
            line_start = m.start() + m.group().rfind("\n") + 1


class FieldLocations:
    """The locations of the fields of one text-format message of type
    `descriptor` (a protobuf Descriptor)."""

    def __init__(self, text, descriptor):
        self._at = {}
        self._tokens = list(tokens(text))
        self._i = 0
        try:
            self._message(descriptor, "", None)
        except (IndexError, KeyError):
            pass  # a file that does not parse: the locations read so far

    def find(self, path):
        """(line, column) of `path` or of its nearest enclosing field; None
        for a top-level field the file does not set."""
        while path:
            if path in self._at:
                return self._at[path]
            path = re.sub(r"\.?[^.\[\]]+(\[\d+\])?$", "", path)
        return None

    def token_after(self, line, column):
        """(line, column) of the token after the one at (line, column)."""
        for k, (_, _, l, c) in enumerate(self._tokens):
            if (l, c) == (line, column) and k + 1 < len(self._tokens):
                return self._tokens[k + 1][2:]
        return None

    def _next(self):
        token = self._tokens[self._i]
        self._i += 1
        return token

    def _peek(self):
        return self._tokens[self._i][1] if self._i < len(self._tokens) else None

    def _message(self, descriptor, prefix, end):
        counts = {}
        while self._i < len(self._tokens):
            kind, text, line, column = self._next()
            if text == end:
                return
            if text in (",", ";"):
                continue
            if text == "[":  # an extension or Any type name: skip to its "]"
                while self._next()[1] != "]":
                    pass
                self._value(None, None)
                continue
            field = descriptor.fields_by_name.get(text) if descriptor is not None else None
            if field is not None and field.label == field.LABEL_REPEATED:
                base = prefix + text
                if self._peek() == ":" and self._tokens[self._i + 1][1] == "[":
                    # protoc's parser records one location for the whole
                    # list, the name's, as that of its first element.
                    self._next()
                    self._next()
                    self._at.setdefault(base, (line, column))
                    self._at.setdefault(f"{base}[{counts.get(text, 0)}]", (line, column))
                    while self._peek() != "]":
                        if self._peek() == ",":
                            self._next()
                            continue
                        k = counts.get(text, 0)
                        counts[text] = k + 1
                        self._value(field, f"{base}[{k}].", element=True)
                    self._next()
                    continue
                k = counts.get(text, 0)
                counts[text] = k + 1
                self._at.setdefault(base, (line, column))
                self._at[f"{base}[{k}]"] = (line, column)
                self._value(field, f"{base}[{k}].")
            else:
                self._at[prefix + text] = (line, column)
                self._value(field, prefix + text + ".")

    def _value(self, field, prefix, element=False):
        if not element and self._peek() == ":":
            self._next()
        opening = self._peek()
        if opening in ("{", "<"):
            self._next()
            nested = field.message_type if field is not None else None
            self._message(nested, prefix, "}" if opening == "{" else ">")
            return
        if opening == "[":  # a list of scalars
            while self._next()[1] != "]":
                pass
            return
        self._next()
        while self._peek() is not None and self._tokens[self._i][0] == "string" and \
                self._tokens[self._i - 1][0] == "string":
            self._next()  # adjacent strings are one value
