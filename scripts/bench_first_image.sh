#!/usr/bin/env bash
# Time to first image: fibscope render versus MRtrix3 mrview, in one run.
#   bench_first_image.sh [--json] [--image IMAGE] [--out DIR] FIBSCOPE_BINARY FILE [RUNS]
#
# Each repetition (RUNS, default 3) times, one after the other:
#   mrview:   mrview IMAGE -imagevisible 0 -noannotations -plane 1
#               -tractography.load FILE -tractography.slab -1 -size 1920,1080
#               -capture.folder DIR -capture.prefix mrview -capture.grab -exit
#             i.e. start, load every streamline, draw them all (slab -1: no
#             crop to a slice, the same work as a whole-brain render), grab
#             the 1920x1080 view to a PNG and quit (coronal plane, i.e. the
#             brain seen from the front; mrview's default pseudotube lines);
#   fibscope: FIBSCOPE_BINARY render FILE --size 1920x1080 -o DIR/fibscope.png
#             (skipped, with a message, when the binary has no `render`).
# Wall clock of each process (date +%s.%N around it); prints every run, the
# medians and the ratio mrview / fibscope; --json prints one JSON object on
# stdout instead (the human-readable lines then go to stderr).
#
# Conditions, stated so the figures can be read right:
#   - warm page cache: FILE is read once (cat > /dev/null) before the first
#     run; the time of a second, cached read is printed as the floor any
#     reader pays;
#   - one Xvfb server (2560x1440x24, so the 1920x1080 view plus mrview's
#     toolbars fits on screen) is started for the whole run and its start-up
#     is NOT counted against mrview (xvfb-run per repetition would add it);
#     under Xvfb mrview renders with Mesa's llvmpipe (software GL);
#   - mrview 3.0.3 grabs nothing unless an image is loaded (it exits 0 without
#     writing a PNG), so IMAGE (default: a 3x3x3 blank image of 80 mm voxels,
#     a 240 mm box centred on the origin, written here) is loaded and hidden;
#     pass the tractogram's anatomical image with --image when the streamlines
#     are not around the origin;
#   - every run must leave its PNG with the right size, or the script fails.
# Exits 77 when mrview or Xvfb is missing (apt-get install mrtrix3 xvfb).
set -euo pipefail

json=0
image=
keep=
while [[ $# -gt 0 && $1 == --* ]]; do
  case $1 in
    --json) json=1; shift ;;
    --image) image=$2; shift 2 ;;
    --out) keep=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
if [[ $# -lt 2 || $# -gt 3 ]]; then
  echo "usage: $0 [--json] [--image IMAGE] [--out DIR] FIBSCOPE_BINARY FILE [RUNS]" >&2
  exit 2
fi
binary=$1
file=$2
runs=${3:-3}
[[ -r $file ]] || { echo "$file: not readable" >&2; exit 2; }
[[ $runs =~ ^[1-9][0-9]*$ ]] || { echo "RUNS must be a positive integer, got '$runs'" >&2; exit 2; }
command -v mrview >/dev/null || { echo "MRtrix3 (mrview) not installed" >&2; exit 77; }
command -v Xvfb >/dev/null || { echo "Xvfb not installed" >&2; exit 77; }

width=1920
height=1080

if [[ $json -eq 1 ]]; then exec 3>&1 1>&2; fi

work=$(mktemp -d /tmp/bench_first_image.XXXXXX)
out=${keep:-$work/out}
mkdir -p "$out"
xvfb_pid=
cleanup() {
  if [[ -n $xvfb_pid ]]; then kill "$xvfb_pid" 2>/dev/null || true; wait "$xvfb_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", b - a }'; }
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { printf "%.3f", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# Width and height from the PNG's IHDR chunk, which must follow the 8-byte
# signature (big-endian, bytes 16-23); anything else (missing, truncated, not
# a PNG) gives 0x0.
png_size() {
  local b
  b=$(od -An -tu1 -N24 "$1" 2>/dev/null | tr -s ' \n' ' ')
  awk -v b="$b" 'BEGIN { n = split(b, v, " ")
    if (n < 24 || v[1] != 137 || v[2] != 80 || v[3] != 78 || v[4] != 71 || v[13] != 73 || v[14] != 72 || v[15] != 68 || v[16] != 82) { print "0x0"; exit }
    printf "%dx%d", ((v[17] * 256 + v[18]) * 256 + v[19]) * 256 + v[20], ((v[21] * 256 + v[22]) * 256 + v[23]) * 256 + v[24] }'
}

if [[ -z $image ]]; then
  # A blank MRtrix image written by hand: text header, data at the offset
  # named by "file: . 256" (truncate pads with zeros, which are the 27 voxels).
  image=$work/blank.mif
  printf '%s\n' 'mrtrix image' 'dim: 3,3,3' 'vox: 80,80,80' 'layout: +0,+1,+2' 'datatype: UInt8' \
    'transform: 1,0,0,-80' 'transform: 0,1,0,-80' 'transform: 0,0,1,-80' 'file: . 256' 'END' > "$image"
  truncate -s $((256 + 27)) "$image"
fi

# -displayfd makes Xvfb choose a free display and write its number once ready.
Xvfb -displayfd 4 -screen 0 2560x1440x24 -nolisten tcp 4>"$work/display" 2>"$work/xvfb.log" &
xvfb_pid=$!
for _ in $(seq 100); do [[ -s $work/display ]] && break; sleep 0.1; done
[[ -s $work/display ]] || { echo "Xvfb did not start:" >&2; cat "$work/xvfb.log" >&2; exit 1; }
DISPLAY=:$(head -1 "$work/display")
export DISPLAY
export XDG_RUNTIME_DIR=$work

have_fibscope=0
# `BINARY render --help` exits 0 even without the subcommand (CLI11 handles
# --help first), so look for it in the subcommand list instead.
if [[ -x $binary ]] && "$binary" --help 2>/dev/null | grep -qE '^[[:space:]]+render([[:space:]]|$)'; then
  have_fibscope=1
else
  echo "fibscope: skipped, '$binary' is not an executable with a 'render' subcommand"
fi

mrview_version=$(mrview -version 2>/dev/null | sed -n 's/^== mrview \(.*\) ==$/\1/p')
gl_renderer=$(mrview "$image" -info -exit 2>&1 | sed -n 's/.*GL renderer: *\([^[:cntrl:]]*\).*/\1/p' | head -1)
echo "file: $file ($(stat -c %s "$file") bytes), view ${width}x${height}, $runs runs, warm page cache"
echo "mrview $mrview_version, GL renderer: ${gl_renderer:-unknown}, DISPLAY=$DISPLAY (Xvfb)"

cat "$file" > /dev/null
t0=$(now); cat "$file" > /dev/null; t1=$(now)
cat_s=$(elapsed "$t0" "$t1")
echo "cat FILE > /dev/null (cached): $cat_s s"

mrview_times=()
fibscope_times=()
for ((i = 1; i <= runs; i++)); do
  rm -f "$out/mrview0000.png"
  t0=$(now)
  status=0
  mrview "$image" -imagevisible 0 -noannotations -plane 1 -tractography.load "$file" -tractography.slab -1 \
    -size "$width,$height" -capture.folder "$out" -capture.prefix mrview -capture.grab -exit \
    > "$work/mrview.log" 2>&1 || status=$?
  t1=$(now)
  got=$(png_size "$out/mrview0000.png")
  if [[ $status -ne 0 || $got != "${width}x${height}" ]]; then
    echo "mrview run $i failed (exit $status, capture ${got}, expected ${width}x${height}); log tail:" >&2
    grep -v -e 'adjustbutton' -e 'QCursor' "$work/mrview.log" | tail -5 >&2
    exit 1
  fi
  mrview_times+=("$(elapsed "$t0" "$t1")")
  line="run $i: mrview ${mrview_times[-1]} s"

  if [[ $have_fibscope -eq 1 ]]; then
    rm -f "$out/fibscope.png"
    t0=$(now)
    status=0
    "$binary" render "$file" --size "${width}x${height}" -o "$out/fibscope.png" > "$work/fibscope.log" 2>&1 || status=$?
    t1=$(now)
    got=$(png_size "$out/fibscope.png")
    if [[ $status -ne 0 || $got != "${width}x${height}" ]]; then
      echo "fibscope run $i failed (exit $status, image ${got}, expected ${width}x${height}); log tail:" >&2
      tail -5 "$work/fibscope.log" >&2
      exit 1
    fi
    fibscope_times+=("$(elapsed "$t0" "$t1")")
    line+=", fibscope ${fibscope_times[-1]} s"
  fi
  echo "$line"
done

mrview_median=$(median "${mrview_times[@]}")
echo "median mrview: $mrview_median s"
fibscope_median=null
ratio=null
if [[ $have_fibscope -eq 1 ]]; then
  fibscope_median=$(median "${fibscope_times[@]}")
  ratio=$(awk -v a="$mrview_median" -v b="$fibscope_median" 'BEGIN { printf "%.1f", a / b }')
  echo "median fibscope: $fibscope_median s"
  echo "mrview / fibscope: ${ratio}x"
fi
if [[ -n $keep ]]; then
  echo "images: $out/mrview0000.png$([[ $have_fibscope -eq 1 ]] && echo " $out/fibscope.png")"
fi

if [[ $json -eq 1 ]]; then
  list() { local IFS=,; echo "[$*]"; }
  esc() { printf '%s' "$1" | sed 's/\\/\\\\/g; s/"/\\"/g'; }
  printf '{"file": "%s", "bytes": %s, "width": %d, "height": %d, "runs": %d, "page_cache": "warm", "cat_s": %s, ' \
    "$(esc "$file")" "$(stat -c %s "$file")" "$width" "$height" "$runs" "$cat_s" >&3
  printf '"mrview_version": "%s", "gl_renderer": "%s", "mrview_s": %s, "mrview_median_s": %s, ' \
    "$(esc "$mrview_version")" "$(esc "$gl_renderer")" "$(list "${mrview_times[@]}")" "$mrview_median" >&3
  if [[ $have_fibscope -eq 1 ]]; then
    printf '"fibscope_s": %s, ' "$(list "${fibscope_times[@]}")" >&3
  else
    printf '"fibscope_s": null, ' >&3
  fi
  printf '"fibscope_median_s": %s, "ratio": %s}\n' "$fibscope_median" "$ratio" >&3
fi
