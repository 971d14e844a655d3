#!/usr/bin/env bash
# Builds the documentation site (Sphinx with MyST) into docs/_build/html; open
# docs/_build/html/index.html. Warnings are errors, which checks every link between the pages
# and every heading a link names; the generated references (docs/elements.md,
# docs/scene-files.md, docs/reference/cpp.md) must be current, and every public Python name
# must have an entry in the Python reference (docs/conf.py). The examples in the pages run in
# the Python tests (tests/python/test_docs.py).
#   bash scripts/docs.sh               the site
#   bash scripts/docs.sh --linkcheck   also the links to other sites (needs the network)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
linkcheck=0
for arg in "$@"; do
  case $arg in
    --linkcheck) linkcheck=1 ;;
    *) echo "docs.sh: unknown option $arg (see the comment at its top)" >&2; exit 1 ;;
  esac
done
bash scripts/setup.sh --no-package --docs  # Sphinx and MyST
# The Python reference reads the installed package's docstrings: it must be this checkout's.
installed=$(.venv/bin/python -c 'import odyn, os; print(os.path.dirname(odyn.__file__))' \
  2>/dev/null) || { echo "docs.sh: install the odyn package first: bash scripts/setup.sh" >&2; exit 1; }
for f in python/odyn/*.py; do
  cmp -s "$f" "$installed/$(basename "$f")" ||
    { echo "docs.sh: the installed odyn is not this checkout's ($f differs):" \
        "bash scripts/setup.sh" >&2; exit 1; }
done
.venv/bin/python -m odyn._generate --check
.venv/bin/python scripts/cpp_reference.py --check
out=docs/_build/html
.venv/bin/python -m sphinx -c docs -b html -W --keep-going -q -E . "$out"
# The site's first page is docs/index.html (the source is the whole repository).
printf '<!doctype html><meta http-equiv="refresh" content="0; url=docs/index.html">\n' \
  > "$out/index.html"
if ((linkcheck)); then
  .venv/bin/python -m sphinx -c docs -b linkcheck -q . docs/_build/linkcheck
fi
echo "docs.sh: the site is in $out (index.html)"
