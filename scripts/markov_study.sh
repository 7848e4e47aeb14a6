#!/usr/bin/env bash
# The Markov chain's accuracy as its maps refine (docs/markov.md): maps of
# more trials per entry bin at fixed bins, then coarser and finer bins at
# the most trials, each validated against 10,000 directly simulated trials
# of the uniform lattice, the C-track and the random asymmetric field,
# under the essay's protocol and as a whole world. With --entries the
# states within a bin are drawn from the gate entries of training sweeps of
# the uniform lattice and the C-track (essay protocol, seed 2, 2000 trials
# each: other trials than the validation's, and not the mixed field);
# without, uniformly in the bin. Prints one row per map, lattice and
# protocol; the runs stay in OUT (default out/markov-study). 10 to 15
# minutes on two cores.
#   scripts/markov_study.sh [--entries] [OUT]
set -euo pipefail
cd "$(dirname "$0")/.."
entries=()
if [ "${1:-}" = "--entries" ]; then
    entries=(1)
    shift
fi
out=${1:-out/markov-study}
exe=build/beamsim
settings=("4,4,3 50" "4,4,3 200" "4,4,3 800" "2,2,2 800" "6,6,4 800")
lattices=(uniform c_track mixed)
mkdir -p "$out"
opts=()
if [ ${#entries[@]} -gt 0 ]; then
    for l in uniform c_track; do
        [ -f "$out/train-$l/gate_entries.csv" ] ||
            $exe sweep configs/markov/$l.yaml --set lattice.protocol=essay --seed 2 --trials 2000 \
                --quiet --out "$out/train-$l"
        opts+=(--entries "$out/train-$l")
    done
fi
printf '%-7s %6s %-8s %-6s %6s %9s %9s %7s %11s %9s\n' bins trials lattice proto tv sampling s95 map gates speedup
for s in "${settings[@]}"; do
    read -r bins trials <<<"$s"
    maps=$out/maps-${bins//,/x}-$trials
    for l in "${lattices[@]}"; do
        $exe markov build configs/markov/$l.yaml --bins "$bins" --trials "$trials" \
            --start-trials "$trials" --train 0 "${opts[@]}" \
            --quiet --out "$maps"
    done
    for l in "${lattices[@]}"; do
        v=$out/validate-${bins//,/x}-$trials-$l
        $exe markov validate configs/markov/$l.yaml --map "$maps" --quiet --out "$v"
        # one check per line of validate.json
        grep '"protocol"' "$v/validate.json" | while read -r line; do
            get() { sed -E "s/.*\"$1\": \"?([^,\"}]*).*/\1/" <<<"$line"; }
            printf '%-7s %6s %-8s %-6s %6.3f %9.3f %9.3f %7.3f %5.2f/%5.2f %9.3g\n' "$bins" "$trials" \
                "$l" "$(get protocol)" "$(get tv)" "$(get tv_sampling)" "$(get tv_sampling95)" \
                "$(get tv_map)" "$(get gates_sim)" "$(get gates_chain)" "$(get speedup)"
        done
    done
done | tee "$out/table.txt"
