#!/usr/bin/env bash
# Install everything the checks need, then lint, type-check and run the whole test suite.
# Usage: bash scripts/test.sh [pytest arguments]
#        bash scripts/test.sh --quick [pytest arguments]   the unit tier only, on two workers
#        (tests/conftest.py marks each test unit, bus, subprocess, browser, system or soak)
set -euo pipefail
cd "$(dirname "$0")/.."

need_debian=()
command -v dot >/dev/null || need_debian+=(graphviz)
# the live-line tests run `cyborg bt run` in a real terminal
command -v tmux >/dev/null || need_debian+=(tmux)
# the monitor's browser tests drive Debian's Chromium (never a downloaded browser)
command -v chromium >/dev/null || need_debian+=(chromium fonts-dejavu-core)
if [ ${#need_debian[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ]; then sudo=(); elif command -v sudo >/dev/null; then sudo=(sudo); else
        echo "scripts/test.sh: please install the Debian packages: ${need_debian[*]}" >&2; exit 1
    fi
    "${sudo[@]}" apt-get update -q
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -q --no-install-recommends \
        "${need_debian[@]}"
fi

# the exact versions that are tested (constraints.txt; pyproject.toml keeps the allowed ranges)
python3 -m pip install -q --disable-pip-version-check -c constraints.txt -e ".[dev]"
python3 -m ruff check src tests benchmarks
python3 -m mypy
if [ "${1:-}" = "--quick" ]; then
    shift
    exec python3 -m pytest -m unit -n 2 "$@"
fi
python3 -m pytest "$@"
