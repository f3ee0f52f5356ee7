#!/bin/sh
# Installs what hybridcont needs to build, test and draw figures, from Debian's registry, if missing.
# Idempotent: does nothing (and needs no network) when everything is present.
#   sh scripts/install-deps.sh        everything: the tool, its figures, the tests (Chromium for the report's),
#                                     the benchmarks and the documentation site (Sphinx, Doxygen, nbsphinx)
#   sh scripts/install-deps.sh tool   what building and running the tool with its figures needs (the README's
#                                     first command: no test frameworks, no SciPy for the reference tests)
set -eu
PACKAGES="g++ cmake make ninja-build libeigen3-dev libboost-dev libcli11-dev nlohmann-json3-dev libfmt-dev libtomlplusplus-dev libssl-dev python3 python3-matplotlib"
case "${1:-all}" in
  tool) ;;
  # The Python package (built by the full build): pybind11's and Python's headers, what the package imports,
  # and venv/pip for its installation test.
  all) PACKAGES="$PACKAGES libgtest-dev libbenchmark-dev python3-pytest python3-scipy chromium pybind11-dev python3-dev python3-numpy python3-pandas python3-sympy python3-tomli-w python3-tqdm python3-venv python3-pip python3-dask python3-distributed python3-sphinx python3-myst-parser furo python3-breathe doxygen python3-nbsphinx python3-nbclient python3-ipykernel pandoc" ;;
  *) echo "usage: sh scripts/install-deps.sh [tool|all]" >&2; exit 2 ;;
esac
missing=""
for p in $PACKAGES; do
  dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
# npm installs the report's plotting library at build time; any npm on PATH will do (Node.js's own included).
command -v npm >/dev/null 2>&1 || missing="$missing npm"
if [ -n "$missing" ]; then
  echo "installing:$missing"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi
