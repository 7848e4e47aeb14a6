#!/usr/bin/env bash
# Maps of a physics against layouts they were not built on (docs/markov.md,
# "Maps of a physics"): the fields of configs/markov/kinds/ (gate kinds
# A = (150, 600), B = (600, 300), C = (300, 150) N m/rad at F_prop = 7 N,
# Rm = 25 N), each simulated directly (10,000 trials, seed 1, both
# protocols) by `markov validate` with the first method's maps, and
# predicted by the maps of every method (`markov predict --out`), whose
# total variation from the same simulation is computed here from
# prediction.csv and validate.csv. A method's maps are built once, on the
# first field of a set of gate kinds, and reused on every other; flow:1
# maps are built per field (they hold for that layout only). Every method
# is markov build --method maps (the walks, markov build's default, are
# measured by markov validate --map on their own build). default is the
# maps' defaults (a training field of 4,000 trials of the kinds whose
# crossings the bins count, topped up to 5 single gates a crossing and at
# most 50, 14,6,13 bins, 16,000 start trials, the first 8,000 continued in
# the gate after the start), train10k the default before it (10,000
# training trials, every start trial continued), crossings0 the one before
# that (50 single gates every bin), start4000 the one before that (4,000
# start trials), uniform the one before that (states uniform in 8,8,9
# bins); the methods after cheap are the settings tried for the default
# now (docs/markov.md, "A smaller training field"). ring5
# and check11 are the fields the settings were chosen on; test_* were made
# after the bins and trials were fixed, fresh_* after the gate after the
# start was, late_* after the training field (method train), final_* after
# the training field with finer bins (method train10k-bins14613), held_*
# after start4000, cheap_* after the cheap maps (method cheap: a training
# field of 4,000 trials counted by its crossings, 5 single gates a bin at
# least, 2,000 from the start; crossings: start4000 counted by its
# crossings, every bin topped up to 50), start_* after crossings0's 16,000
# start trials, per_* after the default's 5 single gates a crossing, pool_*
# after the default's training field of 4,000 trials and its first 8,000
# start trials continued (train10k: the default before), spd_* after the
# speed bins' range from the propulsion, hi_* after its measurement at
# 14 N (name them in FIELDS). Prints one
# row per method and field; the runs stay in OUT (default
# out/markov-kinds), the table in
# OUT/table.txt. FIELDS="..." chooses the fields, METHODS="..." the methods
# (by name), TRIALS=N the direct trials of each (default the experiments',
# 10,000); DIRECT=N adds a row per field, direct-N: a direct simulation of
# its own (N trials, seed 2) against the same validation, what the maps
# are weighed against at that cost. FORCE=F runs every field, build and
# prediction at F_prop = F N (--grid / --set effects.propulsion.force=F;
# an OUT of its own: the validations are named by field only); vmax40 is
# the speed bins' range before it came from the propulsion (docs/markov.md,
# "A speed range from the propulsion": FORCE=14 TRIALS=40000
# METHODS="default vmax40"); per-crossing1-3 top a bin up to fewer single
# gates a crossing ("Fewer single gates a crossing at 7 N"). The other_*
# fields are of a physics of their own (gate kinds D, E and G, F_prop = 8
# N, Rm = 20 N; "A held-out physics"): run them without FORCE.
#   scripts/markov_kinds.sh [OUT] [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/markov-kinds}
threads=${2:-2}
exe=build/beamsim
fields=(${FIELDS:-ring5 check11 test_r7 test_rows9 test_r21a test_r21b fresh_r13 fresh_cols9 fresh_r21})
grid=() set=()
if [ -n "${FORCE:-}" ]; then
    grid=(--grid "effects.propulsion.force=$FORCE")
    set=(--set "effects.propulsion.force=$FORCE")
fi
# method name and its build options (the default: none); uniform, the
# default before, and each of its three parts (fine bins, many start
# trials, the gate after the start) alone and without the others; flow:1;
# self:1 at 8,8,9 bins; uniform at finer bins; uniform with the states of
# a training field's entries (train: the sweep of exp_train_r21.yaml, run
# first), and with 10,000 trials of it and 14,6,13 bins
methods=("default:"
         "train10k:--train 10000 --after-trials 0"
         "crossings0:--train 10000 --after-trials 0 --crossings 0"
         "start4000:--train 10000 --crossings 0 --start-trials 4000"
         "uniform:--train 0 --bins 8,8,9 --start-trials 4000"
         "without-after-start:--train 0 --bins 8,8,9 --after-start 0 --start-trials 4000"
         "fine-bins-alone:--train 0 --bins 8,8,9 --start-trials 50 --after-start 0"
         "start-trials-alone:--train 0 --bins 4,4,3 --trials 200 --after-start 0"
         "after-start-alone:--train 0 --bins 4,4,3 --trials 200 --start-trials 200"
         "previous-default:--train 0 --bins 4,4,3 --trials 200 --start-trials 200 --after-start 0"
         "flow1:--bins 4,4,3 --trials 200 --entries flow:1"
         "self1:--bins 8,8,9 --entries self:1"
         "bins14613:--train 0 --bins 14,6,13 --start-trials 4000"
         "train:--entries $out/train-sweep --bins 8,8,9 --start-trials 4000"
         "train10k-bins14613:--entries $out/train-sweep-10k --bins 14,6,13 --start-trials 4000"
         "crossings:--train 10000 --crossings 1 --per-crossing 0 --start-trials 4000"
         "cheap:--crossings 1 --train 4000 --trials 5 --start-trials 2000"
         "train10k-after8000:--train 10000 --after-trials 8000"
         "train10k-after4000:--train 10000 --after-trials 4000"
         "train10k-no-after:--train 10000 --after-start 0"
         "after-all:--after-trials 0"
         "after4000:--after-trials 4000"
         "no-after:--after-start 0"
         "start4000-no-after:--start-trials 4000 --after-start 0"
         "train3000-no-after:--train 3000 --start-trials 6000 --after-start 0 --trials 20"
         "train2000:--train 2000"
         "vmax40:--vmax 40"
         "per-crossing1:--per-crossing 1"
         "per-crossing2:--per-crossing 2"
         "per-crossing3:--per-crossing 3")
if [ -n "${METHODS:-}" ]; then
    chosen=()
    for m in "${methods[@]}"; do
        for want in $METHODS; do [ "${m%%:*}" = "$want" ] && chosen+=("$m"); done
    done
    methods=("${chosen[@]}")
fi
mkdir -p "$out"
# the training sweeps the methods name: 2,000 trials (the experiment's) and 10,000
for m in "${methods[@]}"; do
    case "${m%%:*}" in
    train) sweep=train-sweep trials=2000 ;;
    train10k-*) sweep=train-sweep-10k trials=10000 ;;
    *) continue ;;
    esac
    [ -f "$out/$sweep/gate_entries.csv" ] ||
        $exe sweep configs/markov/kinds/exp_train_r21.yaml --trials "$trials" --threads "$threads" \
            --quiet --out "$out/$sweep" >/dev/null
done
# TV of validate.csv's p_sim ($1) against another's ($2) for protocol $3
tv_sim() {
    awk -F, -v proto="$3" 'NR == FNR { if (FNR > 1 && $2 == proto) p[$3] = $4; next }
        FNR > 1 && $2 == proto { d = p[$3] - $4; s += d < 0 ? -d : d; seen[$3] = 1 }
        END { for (k in p) if (!(k in seen)) s += p[k]; printf "%.3f", s / 2 }' "$1" "$2"
}
# TV of prediction.csv ($1) against validate.csv's p_sim ($2) for protocol $3
tv() {
    awk -F, -v proto="$3" 'NR == FNR { if (FNR > 1) p[$1] = $5; next }
        FNR > 1 && $2 == proto { d = p[$3] - $4; s += d < 0 ? -d : d; seen[$3] = 1 }
        END { for (k in p) if (!(k in seen)) s += p[k] < 0 ? -p[k] : p[k]; printf "%.3f", s / 2 }' "$1" "$2"
}
printf '%-20s %-11s %6s %6s %9s %9s %9s\n' method field essay world sampling map_cpu_s maps_built
for f in "${fields[@]}"; do
    exp=configs/markov/kinds/exp_$f.yaml
    v=$out/validate-$f
    for m in "${methods[@]}"; do
        name=${m%%:*}
        read -r -a opts <<<"${m#*:}"
        maps=$out/maps-$name
        [ "$name" = flow1 ] && maps=$out/maps-flow1-$f
        log=$($exe markov build "$exp" --method maps "${opts[@]}" "${grid[@]}" --threads "$threads" --out "$maps" 2>&1 | grep -E '^[0-9]+ maps? built' || true)
        # the maps' CPU: what the builds into that directory took (a build
        # that reuses every map adds nothing)
        echo "$log" | sed -n 's/.*built (\([0-9.]*\) s of CPU).*/\1/p' >>"$maps.cpu"
        [ -f "$v/validate.json" ] ||
            $exe markov validate "$exp" --map "$maps" ${TRIALS:+--trials "$TRIALS"} "${grid[@]}" \
                --threads "$threads" --quiet --out "$v"
        p=$out/predict-$name-$f
        $exe markov predict configs/markov/kinds/field_$f.yaml --map "$maps" "${set[@]}" --walks 0 \
            --quiet --overwrite --out "$p"
        cpu=$(awk '{ s += $1 } END { printf "%.1f", s }' "$maps.cpu")
        samp=$(grep '"protocol": "essay"' "$v/validate.json" | sed -E 's/.*"tv_sampling": ([0-9.]*).*/\1/')
        printf '%-20s %-11s %6s %6s %9.3f %9s %s\n' "$name" "$f" "$(tv "$p/prediction.csv" "$v/validate.csv" essay)" \
            "$(tv "$p/prediction.csv" "$v/validate.csv" world)" "$samp" "${cpu:-}" "${log:-}"
    done
    if [ -n "${DIRECT:-}" ]; then
        d=$out/direct$DIRECT-$f
        [ -f "$d/validate.json" ] ||
            $exe markov validate "$exp" --map "$maps" --trials "$DIRECT" --seed 2 "${grid[@]}" \
                --threads "$threads" --quiet --out "$d"
        samp=$(grep '"protocol": "essay"' "$v/validate.json" | sed -E 's/.*"tv_sampling": ([0-9.]*).*/\1/')
        printf '%-20s %-11s %6s %6s %9.3f\n' "direct-$DIRECT" "$f" \
            "$(tv_sim "$d/validate.csv" "$v/validate.csv" essay)" \
            "$(tv_sim "$d/validate.csv" "$v/validate.csv" world)" "$samp"
    fi
done | tee "$out/table.txt"
