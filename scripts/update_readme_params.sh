#!/usr/bin/env bash
# Regenerates the README parameter table (between <!-- params:begin --> and <!-- params:end -->)
# from `spinradar params`, the single parameter definitions.
# Usage: scripts/update_readme_params.sh [--check] [--bin path/to/spinradar] [--readme README.md]
#   --check: change nothing; exit 1 (with a diff) when the table is stale.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
readme="$root/README.md"
bin="${SPINRADAR_BIN:-}"
check=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --check) check=1 ;;
    --bin) bin="$2"; shift ;;
    --readme) readme="$2"; shift ;;
    *) echo "usage: $0 [--check] [--bin spinradar] [--readme README.md]" >&2; exit 2 ;;
  esac
  shift
done
if [[ -z "$bin" ]]; then
  source "$root/scripts/cli_path.sh"
  bin="$(spinradar_cli_path "$root")"
fi
[[ -n "$bin" && -x "$bin" ]] || { echo "error: spinradar binary not found (build first or pass --bin)" >&2; exit 2; }
[[ -f "$readme" ]] || { echo "error: $readme: no such file" >&2; exit 2; }

begin='<!-- params:begin -->'
end='<!-- params:end -->'
grep -qxF "$begin" "$readme" || { echo "error: $readme: marker line '$begin' missing" >&2; exit 2; }
grep -qxF "$end" "$readme" || { echo "error: $readme: marker line '$end' missing" >&2; exit 2; }

table="$(mktemp)"
new="$(mktemp)"
trap 'rm -f "$table" "$new"' EXIT
"$bin" params > "$table"
# Keep everything outside the markers; replace what is between them by the table.
awk -v begin="$begin" -v end="$end" -v table="$table" '
  $0 == begin { print; while ((getline line < table) > 0) print line; skip = 1; next }
  $0 == end   { skip = 0 }
  !skip       { print }
' "$readme" > "$new"

if cmp -s "$readme" "$new"; then
  echo "README parameter table is up to date"
  exit 0
fi
if [[ $check -eq 1 ]]; then
  echo "README parameter table is stale; run scripts/update_readme_params.sh. Difference:" >&2
  diff -u "$readme" "$new" >&2 || true
  exit 1
fi
cp "$new" "$readme"
echo "updated the parameter table in $readme"
