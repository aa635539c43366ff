#!/usr/bin/env bash
# Share of DBC files that load unchanged with the DBC parser of a git revision (docs/results/DBC.md).
#   tests/can/dbc_load_share.sh REV [-v] PATH...
# REV: a git revision of this repository (main, HEAD, a hash), or "." for the work tree as it is.
# PATH: a .dbc file or a folder of them; -v lists each file's warnings. Builds tests/can/dbc_load_share.cpp (of the work tree)
# with that revision's parser sources in a temporary folder, with $CXX (default g++).
set -euo pipefail
if [[ $# -lt 2 ]]; then
  echo "usage: $0 REV [-v] PATH..." >&2
  exit 2
fi
rev=$1
shift
root=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
parts=(client/car/include/dynid/can client/car/src/can core/include/dynid core/src/input)
if [[ $rev == . ]]; then
  (cd "$root" && tar -cf - "${parts[@]}") | tar -xf - -C "$tmp"
else
  git -C "$root" archive "$rev" "${parts[@]}" | tar -xf - -C "$tmp"
fi
echo "parser of ${rev} ($(git -C "$root" rev-parse --short "${rev/#./HEAD}")$([[ $rev == . ]] && echo ', work tree'))"
${CXX:-g++} -std=c++20 -O1 -I"$tmp/client/car/include" -I"$tmp/core/include" -o "$tmp/dbc_load_share" \
  "$root/tests/can/dbc_load_share.cpp" "$tmp"/client/car/src/can/{dbc,dbc_lexer,dbc_parser,dbc_finalize,frame}.cpp \
  "$tmp"/core/src/input/{ids,input_file}.cpp
"$tmp/dbc_load_share" "$@"
