"""JSON files read strictly (issue 80): Python's json keeps the last of a key given twice without a word; here a key
given twice in one object is an error naming it and the keys it sits under ("landmarks.hip_centre"), as the C++
reader (io/subject.cpp) names it. Data after the value ("{...} {...}", "{...} x") is json's own error ("Extra data:
line L column C (char N)")."""
import json


class DuplicateKeyError(ValueError):
    """A key given twice in one object of a JSON text."""


class _Twice:
    """What an object with a key given twice parses to: the key's path, carried up to the top."""

    def __init__(self, path):
        self.path = path


def _twice_in(value):
    """The _Twice in `value` (itself, or in a list, at any depth), or None."""
    if isinstance(value, _Twice):
        return value
    if isinstance(value, list):
        for v in value:
            t = _twice_in(v)
            if t is not None:
                return t
    return None


def _pairs(pairs):
    seen = {}
    for key, value in pairs:
        inner = _twice_in(value)
        if inner is not None:
            return _Twice([key] + inner.path)
        if key in seen:
            return _Twice([key])
        seen[key] = value
    return seen


def loads(text):
    """The JSON value of `text`. Raises ValueError: json.JSONDecodeError on bad JSON or data after the value,
    DuplicateKeyError naming a key given twice in one object."""
    value = json.loads(text, object_pairs_hook=_pairs)
    twice = _twice_in(value)
    if twice is not None:
        raise DuplicateKeyError(f"key '{'.'.join(twice.path)}' appears twice: which value is meant?")
    return value


def load(path):
    """The JSON value of the file `path` (UTF-8, a byte-order mark allowed), as loads() reads a text. OSError when it
    cannot be read; ValueError as loads()."""
    with open(path, encoding="utf-8-sig") as f:
        return loads(f.read())
