#!/usr/bin/env bash
# Calibration and power of `caustic golden` (issue #42; the tables of docs/golden.md).
#
#   scripts/golden_calibration.sh BIN OUT [false|power|cost|all]
#
# false  For every scene in scenes/ and tests/golden_scenes/ (the user-written ones: pool under
#        the sun, glass of water under a spot, dim corner lit through glass, environment-lit
#        room), with the scene's own integrator (the default estimator where none is named)
#        and with `--integrator path`: one `golden update` at W×H, SPP, then N `golden check`s
#        of the unchanged scene with seeds 1001…1000+N. A check that says "changed" (exit 3) is
#        a false alarm. Writes OUT/false.tsv (kind, integrator, scene, alarms, checks, spp) as
#        it goes, so a stopped run keeps what it measured. SPP defaults to 16: at least 12
#        batches, so that the structure test runs besides the block means.
# power  On tests/golden_scenes/pool_sun.ron and scenes/cornell.ron: one `golden update
#        --detect 5%` per scene (the spp it recommends for a 5 % floor), then NP checks of each
#        change against it: a material colour 5 % darker, one light 5 % dimmer, the water's
#        ior 1.33 → 1.36, the ripple amplitude 0.004 → 0.005, 0.006 and 0.008. A check that
#        says "changed" caught it. Writes OUT/power.tsv.
# cost   `golden update --detect 5%` of every scene in scenes/ at W×H, then the CPU time
#        (user + system, /usr/bin/time) of one `golden check scenes/` at those settings, and
#        of each scene's check alone. Writes OUT/cost.tsv.
#
# A stopped `false` run keeps its progress in OUT/false/INTEGRATOR/SCENE/progress ("checks
# alarms" after each check); FIRST=k resumes it at check k (seed 1000+k) with the golden already
# there, and its row then counts checks k…N only.
#
# Environment: N (200), NP (40), W (40), H (30), SPP (16), INTEGRATORS ("default path"), FIRST (1),
# SCENES_ONLY (a space-separated list of scene paths instead of all), THREADS (passed as
# --threads), CASES (power cases in order: "colour sun ior ripple8 ripple6 ripple5 red light").
# Summarize with: scripts/golden_calibration.sh BIN OUT summary (rates with 95 % Wilson
# intervals). Run it in the background on a shared machine:
#   nice -n 10 scripts/golden_calibration.sh target/release/caustic /tmp/gcal all > /tmp/gcal.log 2>&1 &
set -u
BIN=${1:?usage: golden_calibration.sh BIN OUT [false|power|cost|all|summary]}
OUT=${2:?usage: golden_calibration.sh BIN OUT [false|power|cost|all|summary]}
WHAT=${3:-all}
N=${N:-200}
NP=${NP:-40}
W=${W:-40}
H=${H:-30}
SPP=${SPP:-16}
INTEGRATORS=${INTEGRATORS:-default path}
THREADS=${THREADS:-}
FIRST=${FIRST:-1}
CASES=${CASES:-colour sun ior ripple8 ripple6 ripple5 red light}
THREAD_FLAGS=()
if [ -n "$THREADS" ]; then THREAD_FLAGS=(--threads "$THREADS"); fi
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$(cd "$(dirname "$BIN")" && pwd)/$(basename "$BIN")
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
cd "$ROOT" || exit 2

# The user-written scenes first (the progressive ones the issue found failing), then scenes/.
SCENES=(tests/golden_scenes/*.ron scenes/*.ron scenes/*.toml)
if [ -n "${SCENES_ONLY:-}" ]; then
    read -r -a SCENES <<<"$SCENES_ONLY"
fi

flags_for() { # integrator → extra flags
    if [ "$1" = path ]; then echo "--integrator path"; fi
}

false_alarms() {
    for integ in $INTEGRATORS; do
        for scene in "${SCENES[@]}"; do
            name=$(basename "$scene")
            dir="$OUT/false/$integ/$name"
            mkdir -p "$dir"
            # shellcheck disable=SC2046
            if [ "$FIRST" -gt 1 ] && [ -f "$dir/$name.golden" ]; then
                : # resuming: the golden is there
            elif ! "$BIN" golden update "$scene" -o "$dir" --width "$W" --height "$H" --spp "$SPP" \
                $(flags_for "$integ") "${THREAD_FLAGS[@]}" -q >"$dir/update.txt" 2>&1; then
                echo "update failed: $scene ($integ)" >&2
                continue
            fi
            alarms=0
            for i in $(seq "$FIRST" "$N"); do
                "$BIN" golden check "$scene" --golden "$dir" --seed $((1000 + i)) -q \
                    "${THREAD_FLAGS[@]}" --error-dir "$dir/errors" >"$dir/check.txt" 2>&1
                rc=$?
                if [ $rc -eq 3 ]; then
                    alarms=$((alarms + 1))
                    cp "$dir/check.txt" "$dir/alarm_$i.txt"
                elif [ $rc -ne 0 ]; then
                    echo "check failed ($rc): $scene ($integ) seed $((1000 + i))" >&2
                fi
                echo "$((i - FIRST + 1)) $alarms" >"$dir/progress"
            done
            printf 'false\t%s\t%s\t%d\t%d\t%s\n' "$integ" "$name" "$alarms" "$((N - FIRST + 1))" "$SPP" >>"$OUT/false.tsv"
            echo "false alarms: $integ $name $alarms / $N"
        done
    done
}

# golden_for INTEGRATOR SCENE → prints the folder of its `--detect 5%` golden (made once).
golden_for() {
    local integ=$1 scene=$2
    local dir
    dir="$OUT/power/$integ/$(basename "$scene")"
    if [ ! -f "$dir/$(basename "$scene").golden" ]; then
        mkdir -p "$dir"
        # shellcheck disable=SC2046
        "$BIN" golden update "$scene" -o "$dir" --width "$W" --height "$H" --spp "$SPP" --detect 5% \
            $(flags_for "$integ") "${THREAD_FLAGS[@]}" -q >"$dir/update.txt" 2>&1 ||
            echo "update failed: $scene ($integ)" >&2
    fi
    echo "$dir"
}

# power_case INTEGRATOR SCENE LABEL SET...
power_case() {
    local integ=$1 scene=$2 label=$3
    shift 3
    local dir
    dir=$(golden_for "$integ" "$scene")
    [ -f "$dir/$(basename "$scene").golden" ] || return
    local spp
    spp=$(grep -o '[0-9]* spp, ' "$dir/update.txt" | tail -1 | cut -d' ' -f1)
    local caught=0
    local sets=()
    for s in "$@"; do sets+=(--set "$s"); done
    for i in $(seq 1 "$NP"); do
        "$BIN" golden check "$scene" --golden "$dir" --seed $((5000 + i)) -q "${sets[@]}" \
            "${THREAD_FLAGS[@]}" --error-dir "$dir/errors" >"$dir/check.txt" 2>&1
        [ $? -eq 3 ] && caught=$((caught + 1))
    done
    printf 'power\t%s\t%s\t%d\t%d\t%s\n' "$integ" "$label" "$caught" "$NP" "$spp" >>"$OUT/power.tsv"
    echo "power: $integ $label caught $caught / $NP at $spp spp"
}

power() {
    local pool=tests/golden_scenes/pool_sun.ron cornell=scenes/cornell.ron
    for integ in $INTEGRATORS; do
        for case in $CASES; do
            case "$case" in
            colour) power_case "$integ" "$pool" "pool: basin colour -5%" "materials.basin.color=[0.4275, 0.6175, 0.7125]" ;;
            sun) power_case "$integ" "$pool" "pool: sun -5%" "lights[0].irradiance=[2.85, 2.66, 2.375]" ;;
            ior) power_case "$integ" "$pool" "pool: water ior 1.33->1.36" "materials.water.ior=1.36" ;;
            ripple8) power_case "$integ" "$pool" "pool: ripple amplitude 0.004->0.008" "textures.ripples.amplitude=0.008" ;;
            ripple6) power_case "$integ" "$pool" "pool: ripple amplitude 0.004->0.006" "textures.ripples.amplitude=0.006" ;;
            ripple5) power_case "$integ" "$pool" "pool: ripple amplitude 0.004->0.005" "textures.ripples.amplitude=0.005" ;;
            red) power_case "$integ" "$cornell" "cornell: red wall -5%" "materials.red.color=[0.665, 0.114, 0.095]" ;;
            light) power_case "$integ" "$cornell" "cornell: light -5%" "lights[0].power=[42.75, 40.85, 37.05]" ;;
            *) echo "unknown power case \`$case\`" >&2 ;;
            esac
        done
    done
}

cost() {
    local dir="$OUT/cost"
    mkdir -p "$dir"
    "$BIN" golden update scenes/ -o "$dir" --width "$W" --height "$H" --spp "$SPP" --detect 5% -q \
        "${THREAD_FLAGS[@]}" >"$dir/update.txt" 2>&1
    : >"$OUT/cost.tsv"
    for scene in scenes/*.ron scenes/*.toml; do
        /usr/bin/time -f '%U %S %e' -o "$dir/time.txt" \
            "$BIN" golden check "$scene" --golden "$dir" -q "${THREAD_FLAGS[@]}" >/dev/null 2>&1
        local spp
        spp=$(grep "^$scene:" "$dir/update.txt" | grep -o '[0-9]* spp, ' | tail -1 | cut -d' ' -f1)
        read -r user sys wall <"$dir/time.txt"
        printf 'cost\t%s\t%s\t%s\t%s\t%s\n' "$(basename "$scene")" "$spp" "$user" "$sys" "$wall" >>"$OUT/cost.tsv"
        echo "cost: $scene at $spp spp: user $user s, system $sys s, wall $wall s"
    done
    /usr/bin/time -f '%U %S %e' -o "$dir/time.txt" \
        "$BIN" golden check scenes/ --golden "$dir" -q "${THREAD_FLAGS[@]}" >"$dir/check.txt" 2>&1
    read -r user sys wall <"$dir/time.txt"
    echo "cost: golden check scenes/ at the --detect 5% settings: user $user s, system $sys s (CPU $(echo "$user + $sys" | bc) s), wall $wall s" | tee "$OUT/cost.txt"
}

summary() {
    python3 - "$OUT" <<'EOF'
import math, sys, os
out = sys.argv[1]
def wilson(k, n, z=1.96):
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))
for f, title in (("false.tsv", "false alarms"), ("power.tsv", "caught")):
    path = os.path.join(out, f)
    if not os.path.exists(path):
        continue
    print(f"| integrator | scene / change | {title} | rate | 95 % interval | spp |")
    print("|---|---|---|---|---|---|")
    for line in open(path):
        parts = line.rstrip("\n").split("\t")
        integ, name, k, n = parts[1], parts[2], int(parts[3]), int(parts[4])
        lo, hi = wilson(k, n)
        extra = f" {parts[5]} |" if len(parts) > 5 else ""
        print(f"| {integ} | {name} | {k} / {n} | {100*k/n:.1f} % | {100*lo:.1f}–{100*hi:.1f} % |{extra}")
    print()
EOF
}

case "$WHAT" in
false) false_alarms ;;
power) power ;;
cost) cost ;;
summary) summary ;;
all)
    false_alarms
    power
    cost
    summary
    ;;
*)
    echo "unknown part \`$WHAT\`: false, power, cost, all or summary" >&2
    exit 2
    ;;
esac
