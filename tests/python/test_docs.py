"""Every code example of the README and the documentation runs: a page's Python blocks run in
order in one namespace (as a reader would type them), each after the hidden set-up that may
precede it in an HTML comment,

    <!-- example set-up
    m = odyn.Model()
    -->

its JSON scenes load and run, and its C++ blocks are quoted from sources that the test suite or
the examples compile, and run (a block's lines, less indentation, appear in that order in one of
them; a line `// ...` stands for lines left out)."""

import json
import re
import textwrap

import matplotlib
import pytest

import odyn
from odyn import scene
from conftest import ROOT

matplotlib.use("Agg")

FENCE = re.compile(r"^\s*```(\w*)\s*$")  # a block in a list item is indented
SETUP = re.compile(r"<!--\s*example set-up\s*\n(.*?)-->", re.S)

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
# What the test suite and the examples compile and run: where a C++ block must come from.
COMPILED = [p for d in ("tests", "examples") for p in (ROOT / d).rglob("*")
            if p.suffix in (".cpp", ".hpp")]


def blocks(page):
    """(language, code, set-up, line) of each fenced block of a page, in order."""
    text = page.read_text()
    lines = text.splitlines()
    out, i, setup = [], 0, ""
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m and m.group(1):
            start = i
            i += 1
            body = []
            while not FENCE.match(lines[i]):
                body.append(lines[i])
                i += 1
            code = textwrap.dedent("\n".join(body))
            before = "\n".join(lines[:start])
            comments = list(SETUP.finditer(before))
            # The set-up counts only when it ends just before this block (a blank line apart).
            if comments and not before[comments[-1].end():].strip():
                setup = textwrap.dedent(comments[-1].group(1))
            else:
                setup = ""
            out.append((m.group(1), code, setup, start + 1))
        i += 1
    return out


def with_python(page):
    return any(language == "python" for language, *_ in blocks(page))


def run_page(page):
    namespace = {"__name__": "__doc_example__"}
    for language, code, setup, line in blocks(page):
        if language != "python":
            continue
        source = setup + "\n" + code
        try:
            exec(compile(source, f"{page.name}:{line}", "exec"), namespace)
        except Exception as error:  # the block's place, then the error
            raise AssertionError(f"{page.name}, the block at line {line}: "
                                 f"{type(error).__name__}: {error}") from error


@pytest.mark.parametrize("page", [p for p in PAGES if with_python(p)],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_python_examples_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # what an example writes goes there
    run_page(page)


def scenes():
    for page in PAGES:
        for language, code, _, line in blocks(page):
            if language == "json":
                yield pytest.param(page, code, id=f"{page.relative_to(ROOT)}:{line}")


@pytest.mark.parametrize("page, code", list(scenes()))
def test_scene_examples_load_and_run(page, code, tmp_path):
    """A whole scene loads and runs; a part of one ("analysis": {...}) passes the loader's
    checks of its keys."""
    try:
        data = json.loads(code)
    except json.JSONDecodeError:
        data = json.loads("{" + code + "}")  # a part of a scene: its keys and values
    if "bodies" in data:
        path = tmp_path / "scene.json"
        path.write_text(code)
        result = odyn.load(path).run()
        assert result.complete and len(result.t) > 1
        return
    assert set(data) <= set(scene.KEYS["scene"])
    if "analysis" in data:
        scene._check_analysis(data["analysis"], "analysis")


ELISION = "// ..."  # a line of a C++ block that stands for lines of the source left out


def normalized(text):
    return [line.strip() for line in text.splitlines() if line.strip()]


def found_at(have, wanted, start):
    """The index just after the first run of `wanted` in `have` from `start`, or None."""
    for i in range(start, len(have) - len(wanted) + 1):
        if have[i:i + len(wanted)] == wanted:
            return i + len(wanted)
    return None


def quoted_in(code, sources):
    """Whether the block's lines appear in order, together, in one of the sources; a line
    `// ...` stands for any lines of it left out."""
    chunks, chunk = [], []
    for line in normalized(code):
        if line == ELISION:
            chunks.append(chunk)
            chunk = []
        else:
            chunk.append(line)
    chunks = [c for c in chunks + [chunk] if c]
    for source in sources:
        have = normalized(source)
        at = found_at(have, chunks[0], 0)
        while at is not None:
            end = at
            for rest in chunks[1:]:
                end = found_at(have, rest, end)
                if end is None:
                    break
            if end is not None:
                return True
            at = found_at(have, chunks[0], at - len(chunks[0]) + 1)
    return False


def cpp_blocks():
    for page in PAGES:
        for language, code, _, line in blocks(page):
            if language == "cpp":
                yield pytest.param(code, id=f"{page.relative_to(ROOT)}:{line}")


@pytest.fixture(scope="module")
def compiled_sources():
    return [p.read_text() for p in COMPILED]


@pytest.mark.parametrize("code", list(cpp_blocks()))
def test_cpp_examples_are_compiled_sources(code, compiled_sources):
    found = quoted_in(code, compiled_sources)
    assert found, (
        "this C++ block is not part of a compiled source: take it from a test or an example "
        "(or add it to one), so that CI compiles it")


def test_a_set_up_is_seen_and_an_error_names_its_block(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("text\n\n<!-- example set-up\nx = 2\n-->\n```python\ny = x + 1\n```\n\n"
                    "```python\nz = y / 0\n```\n")
    found = blocks(page)
    assert [(lang, code, setup.strip()) for lang, code, setup, _ in found] == [
        ("python", "y = x + 1", "x = 2"), ("python", "z = y / 0", "")]
    with pytest.raises(AssertionError, match="the block at line 10: ZeroDivisionError"):
        run_page(page)


def test_a_cpp_block_not_in_the_sources_is_found_out():
    assert quoted_in("int a = 1;\n  int b = 2;", ["// x\nint a = 1;\nint b = 2;\n"])
    assert not quoted_in("int a = 1;\nint b = 3;", ["int a = 1;\nint b = 2;\n"])
    assert quoted_in("int a = 1;\n// ...\nint c = 3;", ["int a = 1;\nint b = 2;\nint c = 3;"])
    assert not quoted_in("int c = 3;\n// ...\nint a = 1;", ["int a = 1;\nint b = 2;\nint c = 3;"])


def test_the_scene_reference_lists_every_key_the_loader_takes():
    """docs/scene-files.md is written from scene.KEYS; the loader checks against the same
    tables, except the analysis settings and the bodies' keys, which have their own."""
    from odyn import _schema
    assert set(scene.KEYS["analysis"]) == set(scene.ANALYSIS_DEFAULTS) | set(
        scene.ANALYSIS_OPTIONAL)
    assert set(scene.KEYS["bodies"]) == set(_schema.BODY) | set(_schema.PLANAR_BODY) | {"parts"}
    for place, keys in scene.KEYS.items():
        assert all(doc.strip() for doc in keys.values()), place
        assert set(scene.REQUIRED_KEYS.get(place, ())) <= set(keys), place


def test_the_catalogue_names_every_element_type():
    """docs/index.md's catalogue (which the README's capability table summarizes) names every
    element type the compiled core registers, in either space; a new type fails here until it
    is added there."""
    text = (ROOT / "docs" / "index.md").read_text()
    catalogue = text[text.index("## The catalogue in detail"):text.index("## Layout")]
    flat = re.sub(r"[`_\- ]", "", catalogue.lower())
    missing = [t for t in sorted(set(odyn.element_types) | set(odyn.planar_element_types))
               if t not in scene.PYTHON_ONLY and t.replace("_", "") not in flat]
    assert not missing, f"docs/index.md's catalogue does not name {missing}"


def test_the_readme_s_python_example_prints_what_the_readme_shows(capsys):
    text = (ROOT / "README.md").read_text()
    example = text.split("```python\n", 1)[1].split("```\n", 1)[0]
    shown = text.split("It prints", 1)[1].split("```\n", 1)[1].split("```\n", 1)[0]
    exec(compile(example, "README.md", "exec"), {"__name__": "__readme__"})
    assert capsys.readouterr().out == shown
