#!/usr/bin/env bash
# Renders a yawcast report.html in headless Chromium, checks that every section and every
# plot is there and not empty, and saves a screenshot beside the report.
#
#   bash .ci/browser-test.sh [RUN_DIR]
#
# RUN_DIR holds report.html (a `yawcast demo` run directory). Without it, the script runs
# `yawcast demo --seed 1 --out runs/browser-test` first (release build; YAWCAST_PROFILE=ci
# builds with the `ci` profile instead, as .ci/run does).
# Needs Debian's `chromium` (apt-get install -y --no-install-recommends chromium) and perl.
# Leaves RUN_DIR/report.png (the screenshot) and RUN_DIR/report.dom.html (the rendered DOM).
set -euo pipefail
cd "$(dirname "$0")/.."

RUN_DIR=${1:-}
if [ -z "$RUN_DIR" ]; then
    RUN_DIR=runs/browser-test
    cargo run --profile "${YAWCAST_PROFILE:-release}" -q -p yawcast -- demo --seed 1 \
        --out "$RUN_DIR" > /dev/null
fi
RUN_DIR=$(cd "$RUN_DIR" && pwd)
REPORT="$RUN_DIR/report.html"
[ -s "$REPORT" ] || { echo "browser-test: $REPORT is missing or empty" >&2; exit 1; }

CHROME=""
for c in chromium chromium-browser google-chrome; do
    if command -v "$c" > /dev/null 2>&1; then CHROME=$c; break; fi
done
[ -n "$CHROME" ] || {
    echo "browser-test: no chromium (apt-get install -y --no-install-recommends chromium)" >&2
    exit 1
}

PROFILE=$(mktemp -d)
trap 'rm -rf "$PROFILE"' EXIT
FLAGS=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run
       --disable-background-networking --disable-component-update --disable-sync
       --user-data-dir="$PROFILE")
URL="file://$REPORT"

DOM="$RUN_DIR/report.dom.html"
PNG="$RUN_DIR/report.png"
rm -f "$DOM" "$PNG"
timeout 180 "$CHROME" "${FLAGS[@]}" --dump-dom "$URL" > "$DOM" 2> "$RUN_DIR/chromium.log" || {
    echo "browser-test: chromium --dump-dom failed (see $RUN_DIR/chromium.log)" >&2
    exit 1
}
timeout 180 "$CHROME" "${FLAGS[@]}" --hide-scrollbars --window-size=1280,4000 \
    --screenshot="$PNG" "$URL" >> "$RUN_DIR/chromium.log" 2>&1 || {
    echo "browser-test: chromium --screenshot failed (see $RUN_DIR/chromium.log)" >&2
    exit 1
}

# Every section present; every plot section has an <svg> drawing something (a path with
# points, or a polyline); no scripts, no external resources.
perl -0777 -e '
    my $dom = do { local $/; open my $f, "<", $ARGV[0] or die "$ARGV[0]: $!"; <$f> };
    my @plots = qw(data fits parameters residuals regimes diagnosis augmentation firmware);
    my $fail = 0; my $n = 0;
    sub check { my ($ok, $what) = @_; $n++; if ($ok) { print "ok $what\n" } else { print "FAILED $what\n"; $fail++ } }
    check($dom =~ /<section id="summary".*?class="verdict/s, "summary: verdict box");
    for my $id (@plots) {
        my ($sec) = $dom =~ /(<section id="\Q$id\E".*?<\/section>)/s;
        check(defined $sec, "$id: section present");
        next unless defined $sec;
        my @svgs = $sec =~ /(<svg\b.*?<\/svg>)/sg;
        check(scalar(@svgs) > 0, "$id: has a plot");
        my $i = 0;
        for my $s (@svgs) {
            $i++;
            my $drawn = ($s =~ /<path[^>]* d="M\s*[-\d.]+,[-\d.]+[^"]*L/) || ($s =~ /<polyline[^>]* points="[-\d.]+,[-\d.]+ [-\d.]+/) || ($s =~ /<rect x="[\d.]+" y="[\d.]+" width="[\d.]+" height="[\d.]+" fill=/);
            check($drawn, "$id: plot $i draws data");
        }
    }
    check($dom !~ /<script/i, "no scripts");
    check($dom !~ /(?:src|href)="https?:/i, "no external resources");
    my $fails = $fail; my $passes = $n - $fail;
    print "browser-test: $passes passed, $fails failed\n";
    exit($fail ? 1 : 0);
' "$DOM"

# The screenshot: a PNG of 1280 x 4000 pixels.
perl -e '
    open my $f, "<:raw", $ARGV[0] or die "no screenshot $ARGV[0]\n";
    read($f, my $h, 24) == 24 or die "screenshot too short\n";
    substr($h, 0, 8) eq "\x89PNG\r\n\x1a\n" or die "screenshot is not a PNG\n";
    my ($w, $ht) = unpack("NN", substr($h, 16, 8));
    ($w == 1280 && $ht == 4000) or die "screenshot is ${w}x${ht}, expected 1280x4000\n";
    printf "screenshot %s (%dx%d, %d bytes)\n", $ARGV[0], $w, $ht, -s $ARGV[0];
' "$PNG"
