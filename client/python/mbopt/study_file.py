"""Reading a study file for submission, as `mbopt submit` does
(spec/io/study_io.cc): the text-format (or, for a name ending in .json,
JSON) study, with the scene its `scene_file` names (taken from the study's
folder) inlined, and an FMU scene's relative `fmu.path` made absolute from
the scene file's folder. Syntax errors name file:line:column and the field;
what only the study's meaning makes wrong (a bound below its variable's
initial value, an unknown output) the server answers with its own message
on submission (`mbopt validate FILE` names the line of those too).
"""

import os
import re

from google.protobuf import json_format, text_format

from mbopt.errors import StudyFileError
from mbopt.locator import FieldLocations
from mbopt.v1 import scene_pb2, study_pb2

# As spec/limits.h: larger study and scene files are refused before reading.
MAX_INPUT_FILE_BYTES = 16 << 20


def _read_text(path):
    try:
        info = os.stat(path)
    except OSError:
        raise StudyFileError(f"{path}: cannot open file") from None
    if not os.path.isfile(path):
        raise StudyFileError(f"{path}: not a regular file")
    if info.st_size > MAX_INPUT_FILE_BYTES:
        raise StudyFileError(f"{path}: {info.st_size / (1 << 20):.1f} MB, larger than the "
                             f"{MAX_INPUT_FILE_BYTES >> 20} MB limit for study and scene files")
    try:
        with open(path, "rb") as f:
            return f.read().decode("utf-8")
    except UnicodeDecodeError as e:
        raise StudyFileError(f"{path}: not UTF-8 text (byte {e.start})") from None
    except OSError as e:
        raise StudyFileError(f"{path}: cannot open file: {e.strerror}") from None


def _parse(text, path, message):
    """Parses `text` (from `path`) into `message` and returns the locations
    of its fields (None for JSON, which has no lines to name)."""
    if path.endswith(".json"):
        try:
            json_format.Parse(text, message)
        except json_format.ParseError as e:
            raise StudyFileError(
                f"{path}: not a valid {message.DESCRIPTOR.name} in JSON: {e}") from None
        return None
    locations = FieldLocations(text, message.DESCRIPTOR)
    try:
        text_format.Parse(text, message)
    except text_format.ParseError as e:
        line, column = e.GetLine(), e.GetColumn()
        # The library puts "line:column : " before its message; the file
        # name goes in front here, in the compiler's file:line:column form.
        detail = str(e)
        if line is not None and " : " in detail:
            detail = detail.split(" : ", 1)[1]
        if line is not None and "has no field named" in detail:
            # This library points at the unknown name, protoc's parser (and
            # so the CLI) at the token after it: name the same place.
            line, column = locations.token_after(line, column) or (line, column)
        where = f"{path}:{line}:{column}" if line is not None and column is not None else path
        raise StudyFileError(f"{where}: {detail}") from None
    return locations


def _anchor_fmu_path(folder, scene_source, scene):
    if not scene.HasField("fmu") or not scene.fmu.path:
        return
    fmu_path = scene.fmu.path
    if not os.path.isabs(fmu_path):
        fmu_path = os.path.join(folder, fmu_path)
    fmu_path = os.path.normpath(fmu_path)
    if not os.path.isfile(fmu_path):
        raise StudyFileError(f'{scene_source}: fmu.path: no FMU file "{fmu_path}" '
                             f"({scene.fmu.path} is taken from the scene file's folder)")
    scene.fmu.path = fmu_path


# A line of the server's message about a submitted study: "SOURCE: PATH: what".
_SERVER_LINE = re.compile(r"^(?P<source>.+?): (?P<path>[A-Za-z_][A-Za-z0-9_.\[\]]*): (?P<rest>.*)$")


class StudyFile:
    """A study file read for submission: `study` (an mbopt.v1.Study with its
    scene inline) and where its fields are, to name their lines in the
    server's messages about it."""

    def __init__(self, path):
        self.path = os.fspath(path)
        self.study = study_pb2.Study()
        self._locations = _parse(_read_text(self.path), self.path, self.study)
        self.scene_path = None
        self._scene_locations = None
        folder = os.path.dirname(self.path)
        source = self.study.WhichOneof("scene_source")
        if source == "scene_file":
            scene_path = self.study.scene_file
            if not os.path.isabs(scene_path):
                scene_path = os.path.join(folder, scene_path)
            scene_path = os.path.normpath(scene_path)
            if not os.path.exists(scene_path):
                raise StudyFileError(f'{self._where("scene_file")}: scene_file: cannot open scene file "{scene_path}"')
            scene = scene_pb2.Scene()
            self._scene_locations = _parse(_read_text(scene_path), scene_path, scene)
            _anchor_fmu_path(os.path.dirname(scene_path), scene_path, scene)
            self.scene_path = scene_path
            self.study.scene.CopyFrom(scene)  # replaces scene_file (one of the two)
        elif source == "scene":
            _anchor_fmu_path(folder, self.path, self.study.scene)
        else:
            raise StudyFileError(f'{self.path}: scene_file or scene: missing: expected `scene_file: '
                                 f'"name.scene.textproto"` or an inline `scene {{ ... }}`')

    def _where(self, field_path, file=None, locations=None):
        file = file or self.path
        locations = locations if file != self.path else self._locations
        at = locations.find(field_path) if locations is not None else None
        return f"{file}:{at[0]}:{at[1]}" if at else file

    def with_lines(self, message):
        """The server's message about this study (each line "SOURCE: PATH:
        what") with the file and line of each field named, as `mbopt
        validate` names them: a field of the scene in its scene file."""
        out = []
        for text in message.split("\n"):
            m = _SERVER_LINE.match(text)
            if m is None or m["source"] != self.path:
                out.append(text)
                continue
            path, rest = m["path"], m["rest"]
            if self.scene_path is not None and (path == "scene" or path.startswith("scene.")):
                inner = path[len("scene."):]
                out.append(f"{self._where(inner, self.scene_path, self._scene_locations)}: "
                           f"{inner or '(top level)'}: {rest}")
            else:
                out.append(f"{self._where(path)}: {path}: {rest}")
        return "\n".join(out)


def read_study(path):
    """The study at `path` as an mbopt.v1.Study with its scene inline.
    Raises StudyFileError."""
    return StudyFile(path).study
