#!/usr/bin/env bash
# The real-files corpus: Debian's assimp-testmodels (files made by others: .blend files of Blender 2.48-2.79,
# glTF 2 files), fetched once by package name, checked against its pinned checksum and unpacked into
# $SG_PRT_CORPUS_DIR (default .corpus/).  Prints the folder of the models.  Needs apt-get (and, the first
# time on a machine, root for `apt-get update`).
set -euo pipefail
cd "$(dirname "$0")/.."
PACKAGE=assimp-testmodels
VERSION=5.2.5~ds0-1
SHA256=526f326186000cd6f631ea806128548a7d3d391abd8149fddc5c4c8513e80b8a
target=${SG_PRT_CORPUS_DIR:-.corpus}
models="$target/usr/share/assimp/models"
stamp="$target/.sha256"
exec 9>"$target.lock"            # one fetch at a time (every pytest worker asks)
flock 9
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$SHA256" ] && [ -d "$models" ]; then
    echo "$models"
    exit 0
fi
download=$(mktemp -d)
trap 'rm -rf "$download"' EXIT
chmod 777 "$download"           # apt's own user writes there when it can
if ! (cd "$download" && apt-get download -qq "$PACKAGE=$VERSION" >/dev/null 2>&1); then
    apt-get update -qq >/dev/null
    (cd "$download" && apt-get download -qq "$PACKAGE=$VERSION" >/dev/null 2>&1)
fi
deb=$(ls "$download"/*.deb)
echo "$SHA256  $deb" | sha256sum --check --quiet >&2
rm -rf "$target"
mkdir -p "$target"
dpkg-deb -x "$deb" "$target"
echo "$SHA256" > "$stamp"
echo "$models"
