#!/usr/bin/env bash
# Extracts OpenCV's calibration sample images (left01..left14, no left10) and OpenCV's own result
# left_intrinsics.yml from Debian's opencv-doc package into DIR, without installing the package.
# Idempotent: does nothing when the files are already there. Usage: scripts/fetch_test_data.sh DIR
set -euo pipefail

if (($# != 1)); then
  echo "usage: $0 DIR" >&2
  exit 2
fi
dest=$1
prefix=usr/share/doc/opencv-doc/examples/data
names=(left01.jpg left02.jpg left03.jpg left04.jpg left05.jpg left06.jpg left07.jpg left08.jpg
       left09.jpg left11.jpg left12.jpg left13.jpg left14.jpg left_intrinsics.yml)

complete=1
for n in "${names[@]}"; do
  [[ -s "$dest/opencv/$n" ]] || complete=0
done
if ((complete)); then
  exit 0
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
download() { (cd "$work" && apt-get download -q opencv-doc >/dev/null 2>&1); }
if ! download; then
  echo "fetch_test_data: apt-get download opencv-doc failed; running apt-get update and retrying" >&2
  apt-get update -qq >/dev/null
  if ! download; then
    echo "fetch_test_data: cannot download opencv-doc" >&2
    exit 1
  fi
fi
deb=$(ls "$work"/opencv-doc_*.deb)
paths=()
for n in "${names[@]}"; do
  paths+=("./$prefix/$n")
done
mkdir -p "$work/x"
dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$work/x" "${paths[@]}"
mkdir -p "$dest/opencv.tmp"
cp "$work/x/$prefix/"* "$dest/opencv.tmp/"
rm -rf "$dest/opencv"
mv "$dest/opencv.tmp" "$dest/opencv"
echo "fetch_test_data: extracted ${#names[@]} files from $(basename "$deb") into $dest/opencv" >&2
