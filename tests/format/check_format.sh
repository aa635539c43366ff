#!/usr/bin/env bash
# Checks that every C++ line changed since the format baseline follows .clang-format (the lines
# before it are not reformatted wholesale, so history and blame stay readable; a file moved
# without edits has no changed line). The baseline is the commit named in .clang-format-base.
#
#   bash tests/format/check_format.sh [SOURCE_DIR]
#
# Exit 0: clean; 1: lines to format (the diff clang-format wants is printed); 77: not a git
# checkout with the baseline (a source tarball), nothing to compare against.
set -euo pipefail
cd "${1:-$(dirname "$0")/../..}"
formatter=$(command -v clang-format-diff-14 || command -v clang-format-diff || true)
clang_format=$(command -v clang-format-14 || command -v clang-format || true)
[ -n "$formatter" ] && [ -n "$clang_format" ] ||
  { echo "check_format: clang-format(-diff) not found (Debian: clang-format)"; exit 1; }
base=$(sed -e 's/#.*//' -e '/^[[:space:]]*$/d' .clang-format-base | head -1 | tr -d '[:space:]')
if ! git rev-parse -q --verify "$base^{commit}" > /dev/null 2>&1; then
  echo "check_format: baseline $base is not in this checkout; nothing to compare against"
  exit 77
fi
# -M: a moved file counts only for the lines its move changed.
wanted=$(git diff -U0 -M --no-color "$base" -- '*.cpp' '*.hpp' '*.h' | "$formatter" -p1 -style=file)
# A file git does not track yet has no diff: every line of it is new (a checkout before commit).
while IFS= read -r -d '' file; do
  wanted+=$("$clang_format" -style=file "$file" | diff -u --label "$file" --label "$file (formatted)" "$file" - || true)
done < <(git ls-files -z --others --exclude-standard -- '*.cpp' '*.hpp' '*.h')
if [ -n "$wanted" ]; then
  echo "check_format: lines changed since $base do not follow .clang-format; clang-format wants:"
  echo "$wanted"
  exit 1
fi
echo "check_format: every C++ line changed since $base follows .clang-format"
