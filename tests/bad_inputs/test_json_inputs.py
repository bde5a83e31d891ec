"""Issue 80, cases 5/7: a subject.json with a key given twice, or with data after its object ("{...} {...}",
"{...} garbage"), was read without a word (the last value of the key kept; the rest of the file ignored). Now each is
a one-line error naming the file and the key, or the line, column and offset of what follows the object: from the
CLI, from Python's Joint, and from a study that lists the subject."""
import json
import os

import pytest

from conftest import one_line_error, run


def write_subject(folder, generated, text):
    """A copy of the generated hip's subject.json as `text` (its meshes beside it, linked); its path."""
    folder.mkdir()
    for mesh in ("femur_r.ply", "pelvis.ply"):
        os.symlink(os.path.join(os.path.dirname(generated), mesh), folder / mesh)
    (folder / "subject.json").write_text(text)
    return folder / "subject.json"


def position(text, offset):
    """(line, column) of `offset`, 1-based, counted here."""
    before = text[:offset]
    return before.count("\n") + 1, offset - (before.rfind("\n") + 1) + 1


def test_a_key_given_twice_is_named(generated, tmp_path):
    clean = generated.read_text()
    text = clean.replace('"side": "right"', '"side": "right",\n  "side": "left"')
    assert text != clean
    s = write_subject(tmp_path / "d", generated, text)
    one_line_error(run(["distance", "--subject", s, "--out", tmp_path / "o"]), str(s), "key 'side' appears twice")


def test_a_key_given_twice_inside_an_object_is_named_with_its_place(generated, tmp_path):
    info = json.loads(generated.read_text())
    info["landmarks"] = {"hip_centre": [60, -20, 30]}
    text = json.dumps(info, indent=2).replace('"hip_centre": [', '"hip_centre": [60, -20, 31], "hip_centre": [', 1)
    s = write_subject(tmp_path / "d", generated, text)
    one_line_error(run(["distance", "--subject", s, "--out", tmp_path / "o"]), str(s),
                   "key 'landmarks.hip_centre' appears twice")


@pytest.mark.parametrize("after", ['{"side": "left"}', "garbage"])
def test_data_after_the_object_is_named_with_its_line_column_and_offset(generated, tmp_path, after):
    clean = generated.read_text()
    text = clean + "\n" + after + "\n"
    offset = text.index(after, len(clean))
    line, column = position(text, offset)
    s = write_subject(tmp_path / "d", generated, text)
    one_line_error(run(["distance", "--subject", s, "--out", tmp_path / "o"]), str(s),
                   f"line {line}, column {column} (offset {offset}): '{after[:20]}...' after the JSON object")


def test_python_and_studies_say_the_same(generated, tmp_path):
    impinge = pytest.importorskip("impinge")
    from impinge.study import spec
    s = write_subject(tmp_path / "d", generated, generated.read_text().replace('"side": "right"',
                                                                               '"side": "right", "side": "left"'))
    with pytest.raises(impinge.Error, match="key 'side' appears twice"):
        impinge.Joint(subject=str(s), resolution=2.0)
    study = tmp_path / "study.toml"
    study.write_text(f'subjects = ["{s}"]\n[[task]]\nkind = "distance"\nposes = [[0, 0, 0]]\n')
    with pytest.raises(spec.StudyError, match=r"subject\.json: not JSON \(key 'side' appears twice"):
        spec.load_study(str(study))
    # Data after the object: Python's own message (line, column, char), for the study too.
    s2 = write_subject(tmp_path / "e", generated, generated.read_text() + "\n{}\n")
    study.write_text(f'subjects = ["{s2}"]\n[[task]]\nkind = "distance"\nposes = [[0, 0, 0]]\n')
    with pytest.raises(spec.StudyError, match=r"not JSON \(Extra data: line \d+ column 1"):
        spec.load_study(str(study))
