"""Write the type stub impinge/__init__.pyi from its template and the option table (issue 78).

The keyword parameters of Joint(...), Joint.rom_limits, Joint.rom_map, Joint.plan and generated_hip are the option
table's rows (impinge.options()): their keys, types and defaults come from the table, so the stub never holds a
default of its own. A placeholder line in the template,

    @keywords USE [-KEY ...]@

(USE: a `uses` name of impinge.options(); -KEY leaves a row out) is replaced by those rows as `key: type = default`,
wrapped to the placeholder's column within 118 characters. Lines starting "#@" are the template's own comments.

    PYTHONPATH=BUILD/python /usr/bin/python3 python/gen_stub.py TEMPLATE OUT      # write OUT (atomically)
    PYTHONPATH=BUILD/python /usr/bin/python3 python/gen_stub.py TEMPLATE --check STUB  # exit 1 if STUB differs

The build writes BUILD/python/impinge/__init__.pyi this way; python/tests/test_options.py fails when the committed
python/impinge/__init__.pyi differs from it (regenerate it with the first form, OUT = python/impinge/__init__.pyi).
"""
import difflib
import os
import re
import sys
import tempfile

WIDTH = 118
PLACEHOLDER = re.compile(r"@keywords (\w+)((?: -\w+)*)@")


def type_of(row):
    """The annotation of a row's keyword."""
    t, optional = row["type"], row["default"] is None
    base = {"text": "str", "choice": "str", "path": "Union[str, os.PathLike]", "number": "float", "integer": "int",
            "flag": "bool", "on_off": "bool", "numbers": "Sequence[float]", "point": "Union[str, Sequence[float]]",
            "region": "Sequence[float]", "mesh": "Union[str, os.PathLike, Tuple[npt.ArrayLike, npt.ArrayLike]]",
            "landmarks": "Dict[str, Sequence[float]]", "path_pair": "Tuple[str, str]"}[t]
    return f"Optional[{base}]" if optional else base


def default_of(row):
    d = row["default"]
    values = d if isinstance(d, list) else [d]
    if any(isinstance(x, float) and not (x == x and abs(x) != float("inf")) for x in values):
        raise SystemExit(f"gen_stub: the default of '{row['key']}' ({d!r}) is not a finite number: a stub default "
                         "must be a Python literal (give the row a finite default, or teach gen_stub this one)")
    return repr(d)


def wrapped_list(text, column, suffix_len=0):
    """A parameter `text` starting at `column` whose list default runs past WIDTH, broken after its commas and
    aligned after its '['; `suffix_len` characters follow it on its last line."""
    if column + len(text) + suffix_len <= WIDTH or "= [" not in text or "'" in text[text.index("= ["):]:
        return text  # short, no list, or a list of strings (whose items may hold ", "): left whole
    at = text.index("= [") + 3
    head, rest = text[:at], text[at:]
    items, tail = rest[:rest.rindex("]")].split(", "), rest[rest.rindex("]"):]
    inner = column + len(head)
    lines, cur = [], head
    for i, item in enumerate(items):
        last = i + 1 == len(items)
        piece = item + (tail if last else ",")
        used = (column if not lines else inner) + len(cur)
        if not cur.endswith("[") and used + 1 + len(piece) + (suffix_len if last else 0) > WIDTH:
            lines.append(cur)
            cur = piece
        else:
            cur += ("" if cur.endswith("[") else " ") + piece
    lines.append(cur)
    return ("\n" + " " * inner).join(lines)


def render(use, exclude, column, rows, suffix_len, first_column=None):
    """The rows of `use` (table order, less `exclude`) as parameters, wrapped at `column` (the first line starts at
    `first_column`, default `column`); the last line leaves room for the `suffix_len` characters that follow the
    placeholder."""
    first_column = column if first_column is None else first_column
    unknown = exclude - {r["key"] for r in rows if use in r["uses"]}
    if unknown:
        raise SystemExit(f"gen_stub: @keywords {use} leaves out {sorted(unknown)}, which it does not have")
    params = [f"{r['key']}: {type_of(r)} = {default_of(r)}" for r in rows
              if use in r["uses"] and r["key"] not in exclude]
    if not params:
        raise SystemExit(f"gen_stub: no option has the use '{use}'")
    lines, cur = [], ""
    for i, p in enumerate(params):
        last = i + 1 == len(params)
        piece = p + ("" if last else ",")
        room = len(piece) + (suffix_len if last else 0)
        at = first_column if not lines else column
        if cur and at + len(cur) + 1 + room > WIDTH:
            lines.append(cur)
            cur = ""
            at = column
        start = at + (len(cur) + 1 if cur else 0)
        piece = wrapped_list(piece, start, suffix_len if last else 0)
        cur = piece if not cur else cur + " " + piece
        if "\n" in piece and not last:  # a list broken over lines ends its own line
            lines.append(cur)
            cur = ""
    lines.append(cur)
    return ("\n" + " " * column).join(x for x in lines if x)


def open_column(text):
    """The column after the last '(' of `text` that is still open."""
    depth, col = 0, len(text)
    for i in range(len(text) - 1, -1, -1):
        if text[i] == ")":
            depth += 1
        elif text[i] == "(":
            if depth == 0:
                return i + 1
            depth -= 1
    return col


def generate(template_text, rows):
    out = []
    for line in template_text.splitlines(keepends=True):
        if line.startswith("#@"):
            continue  # the template's own comments
        m = PLACEHOLDER.search(line)
        if m:
            exclude = {x for x in m.group(2).split(" -") if x.strip()}
            before, after = line[:m.start()], line[m.end():]
            # After "(..., " the parameters line up inside the parenthesis; on a line of their own, at the placeholder.
            column = open_column(before) if before.rstrip().endswith(",") else m.start()
            body = render(m.group(1), exclude, column, rows, len(after.rstrip("\n")), m.start())
            line = before + body + after
        out.append(line)
    return "".join(out)


def main(argv):
    # This file's folder holds the package's sources (no extension): the built package on PYTHONPATH is wanted.
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != here]
    import impinge
    if len(argv) == 3:
        template, target = argv[1], argv[2]
        text = generate(open(template).read(), impinge.options())
        folder = os.path.dirname(os.path.abspath(target))
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".pyi.")
        try:
            with os.fdopen(fd, "w") as f:
                f.write(text)
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp's file is the owner's only
            os.replace(tmp, target)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
        return 0
    if len(argv) == 4 and argv[2] == "--check":
        text = generate(open(argv[1]).read(), impinge.options())
        have = open(argv[3]).read()
        if text == have:
            return 0
        sys.stdout.writelines(difflib.unified_diff(have.splitlines(True), text.splitlines(True), argv[3], "generated"))
        return 1
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
