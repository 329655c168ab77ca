#!/usr/bin/env bash
# Creates the pinned Python environment of the peer benchmark in bench/peers/.venv
# (ignored by git) and installs requirements.txt into it. Re-running is cheap: the venv is
# rebuilt only when requirements.txt changes.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
req="$here/requirements.txt"
py="${PYTHON:-python3}"

if ! "$py" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 10) else 1)' 2>/dev/null; then
    echo "setup.sh: need Python ≥ 3.10 (sippy-unipi, sysidentpy); found: $("$py" --version 2>&1)" >&2
    exit 2
fi

stamp="$venv/.requirements.sha256"
want="$(sha256sum "$req" | cut -d' ' -f1)-$("$py" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
if [[ -x "$venv/bin/python" && -f "$stamp" && "$(cat "$stamp")" == "$want" ]]; then
    exit 0
fi

echo "setup.sh: creating $venv" >&2
rm -rf "$venv"
"$py" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-input \
    --only-binary=:all: -r "$req"
echo "$want" > "$stamp"
echo "setup.sh: ready ($("$venv/bin/python" --version))" >&2
