#!/usr/bin/env bash
# The Markov chain on held-out fields (docs/markov.md): maps built from
# single gates alone, with states uniform in each bin (self:0, the same
# maps as without --entries), with self-consistent entry states (self:1,
# self:2: each pass's states drawn from the previous pass's exits of the
# same map) and flow-weighted ones (flow:1, flow:2: from every map's exits,
# weighted by the field's chain), at 4,4,3 bins x 800 trials, each
# validated against 10,000 directly
# simulated trials of configs/markov/heldout/field_{a,b,c,d}.yaml under the
# essay's protocol and as a whole world. No map setting was tuned on these
# fields. Prints one row per method, field and protocol; the runs stay in
# OUT (default out/markov-heldout), the table in OUT/table.txt; FIELDS="d"
# chooses the fields (default a b c), TRIALS=N the trials per bin (default
# 800). About 30 minutes on two cores at 800.
#   scripts/markov_heldout.sh [OUT] [THREADS] [METHOD...]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/markov-heldout}
threads=${2:-2}
shift 2 || shift $#
methods=("$@")
[ ${#methods[@]} -gt 0 ] || methods=(self:0 self:1 self:2 flow:1 flow:2)
exe=build/beamsim
trials=${TRIALS:-800}
fields=(${FIELDS:-a b c})
mkdir -p "$out"
printf '%-7s %-6s %-6s %6s %9s %9s %7s %11s\n' entries field proto tv sampling s95 map gates
for m in "${methods[@]}"; do
    # one directory: a build with more passes starts from the last pass there
    maps=$out/maps
    for f in "${fields[@]}"; do
        $exe markov build configs/markov/heldout/exp_$f.yaml --bins 4,4,3 --trials "$trials" \
            --entries "$m" --threads "$threads" --quiet --out "$maps"
    done
    for f in "${fields[@]}"; do
        v=$out/validate-${m/:/}-$f
        $exe markov validate configs/markov/heldout/exp_$f.yaml --map "$maps" \
            --threads "$threads" --quiet --out "$v"
        grep '"protocol"' "$v/validate.json" | while read -r line; do
            get() { sed -E "s/.*\"$1\": \"?([^,\"}]*).*/\1/" <<<"$line"; }
            printf '%-7s %-6s %-6s %6.3f %9.3f %9.3f %7.3f %5.2f/%5.2f\n' "$m" "$f" \
                "$(get protocol)" "$(get tv)" "$(get tv_sampling)" "$(get tv_sampling95)" \
                "$(get tv_map)" "$(get gates_sim)" "$(get gates_chain)"
        done
    done
done | tee -a "$out/table.txt"
