#!/usr/bin/env bash
# Runs a command that must fail cleanly: exit status 1..127 (no crash/signal) and an error
# message matching REGEX (extended grep) on stderr.
# Usage: expect_error.sh REGEX command [args...]
set -uo pipefail
regex="$1"; shift
err="$(mktemp)"
trap 'rm -f "$err"' EXIT
"$@" > /dev/null 2> "$err"
status=$?
cat "$err" >&2
if [[ $status -eq 0 ]]; then echo "FAIL: command succeeded, expected an error" >&2; exit 1; fi
if [[ $status -ge 128 ]]; then echo "FAIL: command crashed (status $status)" >&2; exit 1; fi
if ! grep -Eq -- "$regex" "$err"; then echo "FAIL: error message does not match /$regex/" >&2; exit 1; fi
echo "ok: status $status, message matches /$regex/"
