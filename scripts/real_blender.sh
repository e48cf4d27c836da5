#!/usr/bin/env bash
# Real Blender (Debian trixie's package) in a chroot, for tests that need the
# real binary beside the pip bpy module.  Needs root and deb.debian.org only.
#
#   real_blender.sh setup                                  build the root (idempotent)
#   real_blender.sh run [--bind HOST:GUEST]... -- CMD...   run CMD inside it
#   real_blender.sh status                                 exit 0 iff ready
#
# Env: SGPRT_REAL_BLENDER_ROOT (default /var/cache/sg-prt/real-blender).
set -euo pipefail

ROOT="${SGPRT_REAL_BLENDER_ROOT:-/var/cache/sg-prt/real-blender}"
SUITE=trixie
MIRROR=http://deb.debian.org/debian
# python3-numpy: Debian's Blender does not bring it (official builds ship their own); the add-on needs it
PACKAGES=(blender python3-numpy xvfb xauth imagemagick xdotool libgl1-mesa-dri mesa-utils)
STAMP_FILE=.sg-prt-real-blender.stamp
RECIPE=1  # bump when the setup steps below change, so old roots get rebuilt
# A tiny Workbench render of the factory scene: proves the GL stack (Mesa/EGL) works headless.
RENDER_CHECK="import bpy, os; s = bpy.context.scene; s.render.engine = 'BLENDER_WORKBENCH'
s.render.resolution_x = s.render.resolution_y = 32; s.render.filepath = '/tmp/check.png'
bpy.ops.render.render(write_still=True); assert os.path.getsize('/tmp/check.png') > 0"
GUEST_PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin

log() { printf '[real_blender] %s\n' "$*" >&2; }
die() { log "error: $*"; exit 1; }

# Anything that changes the root's content must change the stamp.
wanted_stamp() { printf '%s %s %s %s\n' "$RECIPE" "$SUITE" "$MIRROR" "${PACKAGES[*]}" | sha256sum | cut -d' ' -f1; }
is_ready() { [[ -f "$ROOT/$STAMP_FILE" && "$(cat "$ROOT/$STAMP_FILE")" == "$(wanted_stamp)" ]]; }

step() {  # step DESCRIPTION CMD... : run CMD, report its wall time
  local desc=$1 t0=$SECONDS; shift
  log "step: $desc"
  "$@"
  log "done: $desc ($((SECONDS - t0)) s)"
}

# Run CMD in a private mount + pid namespace: the chroot's mounts never appear
# in the host's namespace, and everything started inside (e.g. a background
# Xvfb) dies with it.  pdeathsig + the trap make sure that killing this script
# (even with SIGKILL) kills the namespace too; unshare itself ignores SIGTERM.
in_namespace() {
  [[ -e /dev/stdin ]] || exec </dev/null  # "<&0 &" below fails if stdin is closed
  setpriv --pdeathsig KILL unshare --mount --propagation private --pid --kill-child -- "$@" <&0 &
  local pid=$! rc=0
  trap 'kill -KILL $pid 2>/dev/null' INT TERM HUP
  while :; do
    wait "$pid" && rc=0 || rc=$?
    kill -0 "$pid" 2>/dev/null || break  # wait was only interrupted by a signal
  done
  trap - INT TERM HUP
  return "$rc"
}

# _inner CHROOT [--bind H:G]... -- CMD... (runs inside in_namespace)
_inner() {
  local root=$1 bind host guest; shift
  local -a binds=()
  while [[ $# -gt 0 && $1 != -- ]]; do
    [[ $1 == --bind && $# -ge 2 ]] || die "usage: run [--bind HOSTDIR:GUESTDIR]... -- CMD ARGS..."
    binds+=("$2"); shift 2
  done
  [[ $# -ge 2 ]] || die "usage: run [--bind HOSTDIR:GUESTDIR]... -- CMD ARGS..."
  shift
  mount -t proc proc "$root/proc"
  mount -t sysfs sysfs "$root/sys"
  mount --rbind /dev "$root/dev"
  mount -t tmpfs -o mode=1777 tmpfs "$root/dev/shm"
  # Fresh /tmp each run, so stale X lock files or sockets never leak between runs.
  mount -t tmpfs -o mode=1777 tmpfs "$root/tmp"
  for bind in "${binds[@]}"; do
    host=${bind%%:*} guest=${bind#*:}
    [[ $bind == *:* && -e $host && $guest == /* ]] || die "bad --bind '$bind' (need existing HOSTDIR and absolute GUESTDIR)"
    if [[ -d $host ]]; then mkdir -p "$root$guest"; else mkdir -p "$(dirname "$root$guest")"; touch "$root$guest"; fi
    mount --rbind "$host" "$root$guest"
  done
  local -a env=(HOME=/root "PATH=$GUEST_PATH" LANG=C.UTF-8 DEBIAN_FRONTEND=noninteractive)
  [[ -n ${DISPLAY:-} ]] && env+=("DISPLAY=$DISPLAY")
  [[ -n ${TERM:-} ]] && env+=("TERM=$TERM")
  # Not exec: bash stays PID 1 of the namespace, so CMD gets normal signal
  # handling and its exit code is passed back.
  local rc=0
  chroot "$root" /usr/bin/env -i "${env[@]}" "$@" || rc=$?
  exit "$rc"
}

run_in() { local root=$1; shift; in_namespace bash "${BASH_SOURCE[0]}" _inner "$root" "$@"; }

cmd_setup() {
  mkdir -p "$(dirname "$ROOT")"
  # One setup at a time; a second caller waits, then sees the stamp.
  exec 9>"$ROOT.lock"
  flock 9
  if is_ready; then log "root ready at $ROOT (stamp matches)"; return 0; fi
  # Leftovers of a setup that was SIGKILLed (no trap could run); we hold the lock.
  rm -rf --one-file-system "$ROOT".tmp.* "$ROOT".old.*

  if ! command -v debootstrap >/dev/null; then
    step "host: apt-get install debootstrap" \
      bash -c 'apt-get install -y debootstrap || { apt-get update && apt-get install -y debootstrap; }'
  fi

  # Build in a sibling temp dir; it becomes $ROOT only after everything worked.
  # The chroot's mounts live in private namespaces, so rm -rf never reaches the host.
  local old
  TMP_ROOT=$(mktemp -d "$ROOT.tmp.XXXXXX")
  chmod 755 "$TMP_ROOT"  # mktemp makes it 0700, which locks out _apt and other guest users
  trap 'rm -rf --one-file-system "$TMP_ROOT"' EXIT
  local tmp=$TMP_ROOT
  step "debootstrap --variant=minbase $SUITE" \
    in_namespace debootstrap --variant=minbase "$SUITE" "$tmp" "$MIRROR"
  cp /etc/resolv.conf "$tmp/etc/resolv.conf"
  # minbase has no /etc/mtab; without it Blender warns it cannot list file systems.
  ln -sf ../proc/self/mounts "$tmp/etc/mtab"
  echo "deb $MIRROR $SUITE main" >"$tmp/etc/apt/sources.list"
  step "chroot: apt-get update" run_in "$tmp" -- apt-get update
  step "chroot: apt-get install ${PACKAGES[*]}" \
    run_in "$tmp" -- apt-get install -y --no-install-recommends "${PACKAGES[@]}"
  step "chroot: apt-get clean" run_in "$tmp" -- apt-get clean
  step "check: blender -b --version" run_in "$tmp" -- blender -b --version
  step "check: background Workbench render" run_in "$tmp" -- \
    blender -b --factory-startup --python-exit-code 1 --python-expr "$RENDER_CHECK"
  wanted_stamp >"$tmp/$STAMP_FILE"

  old="$ROOT.old.$$"
  [[ -e $ROOT ]] && mv -T "$ROOT" "$old"
  mv -T "$tmp" "$ROOT"
  trap - EXIT
  rm -rf --one-file-system "$old"
  log "root ready at $ROOT ($(du -sh "$ROOT" | cut -f1))"
}

cmd_status() {
  if [[ ! -d $ROOT ]]; then echo "not ready: $ROOT does not exist (run: $0 setup)"; return 1; fi
  if [[ ! -f $ROOT/$STAMP_FILE ]]; then echo "not ready: $ROOT has no stamp (incomplete; run: $0 setup)"; return 1; fi
  if ! is_ready; then echo "not ready: stamp in $ROOT is stale (package list or recipe changed; run: $0 setup)"; return 1; fi
  local v
  v=$(run_in "$ROOT" -- blender -b --version 2>/dev/null | grep -m1 '^Blender') || { echo "not ready: blender in $ROOT does not start"; return 1; }
  echo "ready: $ROOT ($v)"
}

[[ $(id -u) == 0 ]] || die "must run as root (chroot, mounts)"
case "${1:-}" in
  setup) cmd_setup ;;
  run) shift; is_ready || die "root not ready at $ROOT (run: $0 setup)"; run_in "$ROOT" "$@" ;;
  status) cmd_status ;;
  _inner) shift; _inner "$@" ;;
  *) die "usage: $0 setup | status | run [--bind HOSTDIR:GUESTDIR]... -- CMD ARGS..." ;;
esac
