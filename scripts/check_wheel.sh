# check_wheel WHEEL: the wheel's sha256 is the one scripts/wheels.sha256 pins for its file
# name, else an error naming both (sourced by the setup scripts).
check_wheel() {
  local wheel="$1" name want got
  name="$(basename "$wheel")"
  want="$(awk -v n="$name" '$2 == n {print $1}' "$(dirname "${BASH_SOURCE[0]}")/wheels.sha256")"
  got="$(sha256sum "$wheel" | cut -d' ' -f1)"
  if [[ -z "$want" ]]; then
    echo "setup: $name has no pinned sha256 in scripts/wheels.sha256 (this one is $got)" >&2
    return 1
  fi
  if [[ "$got" != "$want" ]]; then
    echo "setup: $name has sha256 $got, scripts/wheels.sha256 pins $want: delete it and run setup again" >&2
    return 1
  fi
}
