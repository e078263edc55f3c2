#!/usr/bin/env bash
# Runs a command only when shared/realdata exists; otherwise exits 77 (ctest: skipped) with a
# message. Usage: with_realdata.sh SHARED_DIR COMMAND...
set -euo pipefail
shared="$1"; shift
if [[ ! -d "$shared/realdata" ]]; then
  echo "SKIP: $shared/realdata not found (needs shared/ beside the clone)" >&2; exit 77
fi
exec "$@"
