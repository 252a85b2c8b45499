#!/usr/bin/env bash
# Idempotent setup: Debian libraries where missing, then `.venv` with `pip install -e '.[dev]'`,
# the packages the figures depend on pinned by constraints.txt. Re-running is cheap: pip is only
# called again when pyproject.toml or constraints.txt changes.
set -euo pipefail
cd "$(dirname "$0")/.."

# EGL + Mesa: MuJoCo renders depth headless through EGL.
# chromium: the console's browser tests. nginx: the deploy test.
DEB_PACKAGES=(libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 chromium nginx-light)

missing=()
for pkg in "${DEB_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if ((${#missing[@]})); then
    echo "bootstrap: installing Debian packages: ${missing[*]}"
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

PYTHON="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
    echo "bootstrap: creating .venv"
    "$PYTHON" -m venv .venv
fi

stamp=.venv/.laserpick-installed
want=$(cat pyproject.toml constraints.txt | sha256sum | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
    echo "bootstrap: pip install -e '.[dev]' -c constraints.txt"
    .venv/bin/python -m pip install -q --upgrade pip
    .venv/bin/python -m pip install -q -e '.[dev]' -c constraints.txt
    echo "$want" > "$stamp"
fi
