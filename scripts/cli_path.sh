# Sourced by scripts: `spinradar_cli_path ROOT` prints the built `spinradar` CLI ($SPINRADAR_BIN
# when set, else the catkin or plain-CMake build under ROOT/build), or nothing when none exists.
spinradar_cli_path() {
  local root="$1" b
  if [[ -n "${SPINRADAR_BIN:-}" ]]; then echo "$SPINRADAR_BIN"; return; fi
  for b in "$root/build/devel/lib/spinradar/spinradar" "$root/build/bin/spinradar"; do
    [[ -x "$b" ]] && { echo "$b"; return; }
  done
}
