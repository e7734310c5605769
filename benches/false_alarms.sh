#!/usr/bin/env bash
# How often `compare` fails an honest render of the later weeks' and the book's built-in scenes.
#
#   benches/false_alarms.sh RTORACLE [SEEDS] [SCENES] [SPPS]
#
# For each built-in scene of weeks 5 to 10 and of book 1, renders it with the reference at
# SEEDS seeds (default 40; the goldens use another seed), full size, as the 8-bit PNG a student
# hands in, at the scene's own spp and at a grader's spp (4, the week-8 rubric's; 5 for the
# jittered scenes of weeks 9 and 10, as their rubrics render them), and judges each with
# `rtoracle compare --scene NAME --spp N` against its golden (embedded in the binary, or rendered
# once into a private cache). SCENES, an extended regular expression, keeps the scenes whose
# names it matches; SPPS `grader` skips the scenes' own spp, and a number renders at that spp only
# (2: the weekly rubrics' spp for weeks 5 to 7). Every render is honest, so every
# failure is a false alarm. Prints one line per scene and spp: the failures, and the smallest
# adjusted p over the seeds at each scale and of the noise-level test. Needs python3 for reading
# the JSON reports. At their own spp, the scenes of more than 40 spp need a golden of 100 x their
# spp rendered first, once into the script's cache (week 10's and the book's: with their renders,
# about 23 minutes on a 2-core machine); the rest takes about a quarter of an hour.
set -euo pipefail
bin=$(realpath "$1")
seeds=${2:-40}
only=${3:-.}
spps=${4:-both}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT INT TERM
export RTORACLE_CACHE_DIR="$work/cache"

scenes=$("$bin" scenes | awk '($2 == "week" && $3 >= 5) || $2 == "book" {print $1}' | grep -E -- "$only")
total=0
failed=0
for scene in $scenes; do
    own=$("$bin" scenes --dump "$scene" | awk -F' = ' '/^samples_per_pixel/ {print $2}')
    scene_spp=$own
    grader=4
    jittered=no
    if "$bin" scenes --dump "$scene" | grep -q '^sampling = "course-jittered"'; then
        grader=5
        jittered=yes
    fi
    encoding=course
    if "$bin" scenes --dump "$scene" | grep -q '^profile = "physical"'; then
        encoding=rtiow
    fi
    [ "$spps" = grader ] && own=$grader
    if [[ "$spps" =~ ^[0-9]+$ ]]; then
        grader=$spps
        own=$spps
    fi
    for spp in $(printf '%s\n' "$grader" "$own" | uniq); do
        # A jittered scene's image depends on its own samples_per_pixel (its strata, and what
        # their sum is divided by): at another spp it is that scene with samples_per_pixel = spp,
        # as a course program of that spp renders it (its golden rendered once into the cache).
        source=$scene
        if [ "$jittered" = yes ] && [ "$spp" != "$scene_spp" ]; then
            source="$work/$scene-${spp}spp.toml"
            "$bin" scenes --dump "$scene" |
                sed -e "s/^samples_per_pixel = .*/samples_per_pixel = $spp/" > "$source"
        fi
        fails=0
        : > "$work/p.txt"
        for seed in $(seq 1 "$seeds"); do
            "$bin" render "$source" --spp "$spp" --seed "$seed" -o "$work/c.png" 2>/dev/null
            if ! "$bin" compare --scene "$source" --spp "$spp" --encoding "$encoding" --json \
                "$work/c.png" > "$work/r.json"; then
                fails=$((fails + 1))
            fi
            python3 - "$work/r.json" >> "$work/p.txt" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
print(" ".join([str(s["smallest_adjusted_p"]) for s in r["scales"]] + [str(r["noise"]["p"])]))
EOF
        done
        mins=$(python3 -c '
import sys
rows = [list(map(float, l.split())) for l in open(sys.argv[1]) if l.strip()]
print(" ".join(f"{min(c):.3g}" for c in zip(*rows)))' "$work/p.txt")
        printf '%-26s %3s spp  %d of %d fail   smallest p (pixel tile8 tile32 global noise): %s\n' \
            "$scene" "$spp" "$fails" "$seeds" "$mins"
        total=$((total + seeds))
        failed=$((failed + fails))
    done
done
echo "all: $failed of $total honest renders fail"
