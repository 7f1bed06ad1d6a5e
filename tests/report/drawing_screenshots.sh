#!/usr/bin/env bash
# Screenshots of scene drawings for docs/report.md, in headless Chromium,
# each page opened at one frame of its animation ("#frame=N"):
#  - `mbopt draw` on the press, the isolator, the four-bar, the vehicle and
#    the suspension (a spatial scene):
#    docs/images/drawing_<scene>.png;
#  - the report of the press, isolator and vehicle studies optimized with
#    `mbopt run`, its top (header and "Mechanism"):
#    docs/images/report_<study>.png;
#  - sections of those reports alone (the page's head and the sections
#    from one heading up to the next one not asked for): the press's x-y
#    plots and responses, the isolator's responses, the tables of all three:
#    docs/images/report_<study>_<part>.png.
# Needs the three built programs and Chromium (deploy/install-deps.sh).
#   usage: bash tests/report/drawing_screenshots.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
chromium=${MBOPT_CHROMIUM:-/usr/bin/chromium}
out=$root/docs/images
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export MBOPT_WORKER_BIN=$build/worker/main/mbopt-worker
export MBOPT_SERVER_BIN=$build/server/main/mbopt-server
mkdir -p "$out"
cd "$root"  # the pages name their files relative to the tree

# $1 page, $2 frame, $3 window width, $4 height, $5 the PNG
screenshot() {
  timeout 120 "$chromium" --headless --no-sandbox --disable-gpu --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync --hide-scrollbars \
    --user-data-dir="$work/profile-$(basename "$5")" --window-size="$3,$4" \
    --screenshot="$5" "file://$1#frame=$2" >/dev/null 2>"$work/chromium.err" ||
    { cat "$work/chromium.err" >&2; exit 1; }
  echo "wrote $5"
}

# scene file, frame shown, window height (px)
scenes=(
  "press/press.scene.textproto 30 350"
  "isolator/isolator.scene.textproto 40 700"
  "fourbar/fourbar_rigid.scene.textproto 20 680"
  "vehicle/vehicle.scene.textproto 0 700"
  "suspension/suspension.scene.textproto 28 800"
)
for scene in "${scenes[@]}"; do
  read -r file frame height <<<"$scene"
  name=$(basename "$file" .scene.textproto)
  "$build/client/mbopt" draw "examples/$file" -o "$work/$name.html"
  screenshot "$work/$name.html" "$frame" 780 "$height" "$out/drawing_$name.png"
done

# $1 report page, $2 the page to write, $3... the <h2> headings kept
section_page() {
  python3 - "$@" <<'PY'
import sys
page, out, keep = sys.argv[1], sys.argv[2], sys.argv[3:]
html = open(page, encoding="utf-8").read()
head, _, body = html.partition("<h2>")
head = head[:head.index("<body>") + len("<body>")] if "<body>" in head else head
parts = ["<h2>" + p for p in body.split("<h2>")]
kept = [p for p in parts if any(p.startswith("<h2>" + k + "</h2>") for k in keep)]
if len(kept) != len(keep):
    sys.exit("section_page: not every heading of %s is in %s" % (keep, page))
text = "".join(kept)
if "</body>" not in text:
    text += "</body>\n</html>\n"
open(out, "w", encoding="utf-8").write(head + "\n" + text)
PY
}

# study file, frame shown, window height (px)
reports=(
  "press/press.study.textproto 40 560"
  "isolator/isolator.study.textproto 40 1000"
  "vehicle/vehicle.study.textproto 0 880"
)
for report in "${reports[@]}"; do
  read -r file frame height <<<"$report"
  name=$(basename "$file" .study.textproto)
  "$build/client/mbopt" run "examples/$file" --workers 2 --db "$work/$name.db" --quiet
  "$build/client/mbopt" report job-1 --db "$work/$name.db" -o "$work/${name}_report.html"
  screenshot "$work/${name}_report.html" "$frame" 1000 "$height" "$out/report_$name.png"
done

# report, part name, window width and height (px), headings
sections=(
  "press xy 1000 740|Plots of one response against another"
  "press responses 1000 900|Responses at the initial and final designs"
  "isolator responses 1000 560|Responses at the initial and final designs"
  "press tables 1280 640|Final design|Active constraints|Cycles"
  "isolator tables 1280 1000|Final design|Active constraints|Cycles"
  "vehicle tables 1280 900|Final design|Active constraints|Cycles"
)
for section in "${sections[@]}"; do
  IFS='|' read -r -a fields <<<"$section"
  read -r name part width height <<<"${fields[0]}"
  section_page "$work/${name}_report.html" "$work/${name}_$part.html" "${fields[@]:1}"
  screenshot "$work/${name}_$part.html" 0 "$width" "$height" "$out/report_${name}_$part.png"
done
