#!/usr/bin/env bash
# Renders the same frames with two fibscope binaries and says whether every
# pixel agrees: the check that a refactoring changed nothing a user sees.
#   scripts/compare_renders.sh OLD_FIBSCOPE NEW_FIBSCOPE [TRACTOGRAM...]
# Without tractograms: the built-in phantom and an MRtrix3 iFOD1 tractogram
# (tests/tools/mrtrix_fod_tractograms.sh, when MRtrix3 is installed). Each
# is drawn from the three standard views in every pipeline, colour mode and
# lighting (and once with FXAA, multi-scale AO and no SSAO), at 320x200,
# by both binaries one after the other; the PNGs' decoded pixels are
# compared (a small PNG decoder in Python below, so that two PNG writers
# that filter or compress differently still compare by pixels). Prints one
# line per difference and a summary; exits 1 when any pixel differs.
set -euo pipefail
old=$1 new=$2
shift 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
inputs=("$@")
if [ ${#inputs[@]} -eq 0 ]; then
  inputs=(phantom)
  if "$(dirname "$0")/../tests/tools/mrtrix_fod_tractograms.sh" "$work/mrtrix" 300 >/dev/null 2>&1; then
    inputs+=("$work/mrtrix/ifod1.tck")
  else
    echo "compare_renders: MRtrix3 not available, phantom only" >&2
  fi
fi
same() {  # same A.png B.png: exit 0 when every pixel is equal
  cmp -s "$1" "$2" && return 0
  python3 - "$1" "$2" <<'PY'
import struct, sys, zlib
def pixels(path):
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', path
    at, idat, w, h, bpp = 8, b'', 0, 0, 0
    while at < len(data):
        n, kind = struct.unpack('>I4s', data[at:at + 8])
        body = data[at + 8:at + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
            assert depth == 8 and ctype in (2, 6), path
            bpp = 4 if ctype == 6 else 3
        elif kind == b'IDAT':
            idat += body
        at += 12 + n
    raw, stride, out, prev = zlib.decompress(idat), w * bpp, bytearray(), bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out += line
        prev = line
    return w, h, bpp, bytes(out)
sys.exit(0 if pixels(sys.argv[1]) == pixels(sys.argv[2]) else 1)
PY
}
frames=0 differ=0
for input in "${inputs[@]}"; do
  file=()
  [ "$input" = phantom ] && file=(--phantom-streamlines 3000) || file=("$input")
  cases=()
  for view in sagittal coronal axial; do
    for pipeline in compute lines raw-compute; do
      for color in orientation solid fiber scalar normal; do
        for lighting in illuminated none; do
          cases+=("--view $view --pipeline $pipeline --color $color --lighting $lighting")
        done
      done
    done
  done
  cases+=("--view axial --fxaa" "--view coronal --ao-scales 3" "--view sagittal --no-ssao"
          "--view axial --culling two-phase" "--view coronal --culling none --line-width 2")
  for c in "${cases[@]}"; do
    # shellcheck disable=SC2086
    "$old" render "${file[@]}" --size 320x200 $c -o "$work/old.png" >/dev/null
    # shellcheck disable=SC2086
    "$new" render "${file[@]}" --size 320x200 $c -o "$work/new.png" >/dev/null
    frames=$((frames + 1))
    if ! same "$work/old.png" "$work/new.png"; then
      differ=$((differ + 1))
      echo "differs: $(basename "$input") $c"
    fi
  done
done
echo "compare_renders: $frames frames, $differ differ"
[ "$differ" -eq 0 ]
