#!/usr/bin/env bash
# Redraws docs/figures/, the essay's figures that the docs show, from
# fresh runs in out/figures/ (the commands are the docs'). The copies in
# docs/ are the PNGs drawn again by their own scripts at 0.75 of their size.
set -euo pipefail
cd "$(dirname "$0")/.."
b=build/beamsim
o=out/figures
d=docs/figures
mkdir -p "$o" "$d"

# Fig. 2.2: the random force of one trial at Rm = 20 N (the gate's default)
$b run configs/thesis/gate.yaml --out $o/fig2.2 >/dev/null
# Fig. 2.7: a trial whose path runs below the landscape (H1 group 13, trial 15)
$b run configs/thesis/h1_symmetric.yaml --group 13 --trial 15 --out $o/fig2.7 >/dev/null
# Fig. 3.1: H1
$b sweep configs/thesis/h1_symmetric.yaml --quiet --out $o/h1
# Figs. 3.2, 3.3: the H2 groups the essay draws, every trajectory kept
$b sweep configs/thesis/h2_figures.yaml --trajectories 100 --quiet --out $o/h2-figures
# Fig. 3.4: H2, and the two slices the essay draws
$b sweep configs/thesis/h2_asymmetric.yaml --quiet --out $o/h2
for dir in fig2.2 fig2.7 h1 h2-figures; do $b plot $o/$dir --quiet; done
$b plot $o/h2 --select effects.propulsion.force=8 --select effects.random_force.magnitude=30 \
  --out $o/fig3.4a --quiet
$b plot $o/h2 --select effects.propulsion.force=8 --select beams.0.stiffness=300 \
  --out $o/fig3.4b --quiet
# Fig. 2.6: the landscape of the essay gate, of the essay's asymmetric 500 : 250 gate, and of
# H2's 100 : 500 gate
$b landscape configs/thesis/gate.yaml --out $o/landscape >/dev/null
$b landscape configs/thesis/gate.yaml --set beams.0.stiffness=500 --set beams.1.stiffness=250 \
  --out $o/landscape-500-250 >/dev/null
$b landscape configs/thesis/gate.yaml --set beams.0.stiffness=100 --set beams.1.stiffness=500 \
  --out $o/landscape-100-500 >/dev/null
# Fig. 3.5: the C-track of the gate lattice, the essay's 20 trials; its 1000 trials on both
# protocols (the first 200 trajectories kept) and on both backends (compare exits 3 on a
# disagreement, which is a result here, not a failure)
$b sweep configs/lattice/c_track_essay.yaml --trajectories 20 --trajectory-stride 25 --quiet \
  --out $o/c-track-20
$b compare configs/lattice/c_track_1000.yaml --protocols world,essay --trajectories 200 \
  --trajectory-stride 25 --quiet --out $o/c-track-protocols || [ $? -eq 3 ]
$b compare configs/lattice/c_track_1000.yaml --quiet --out $o/c-track-backends || [ $? -eq 3 ]
for dir in c-track-20 c-track-protocols c-track-backends; do $b plot $o/$dir --quiet; done
# the accuracy study of docs/accuracy.csv
mkdir -p $o/accuracy && cp docs/accuracy.csv $o/accuracy/ && $b plot $o/accuracy --quiet
# docs/first_passage.md: H1 at a 24 s horizon, the 9 N groups' survival
$b sweep configs/thesis/h1_symmetric.yaml --set integration.duration=24 --quiet --out $o/h1-24
$b plot $o/h1-24 --select effects.propulsion.force=9 --out $o/h1-24-9N --quiet
# docs/essay.md: the essay's levels beside beamsim's (the table's run, without --sensitivity)
$b essay --quiet --out $o/essay

small() { # small DIR NAME COPY: DIR/NAME.gp drawn again at 0.75 as docs/figures/COPY.png
  (cd "$1" && gnuplot -e "scale=0.75; outbase=\"small-$2\"" "$2.gp" && rm -f "small-$2.svg")
  mv "$1/small-$2.png" "$d/$3.png"
}
small $o/fig2.2 random_force fig2.2-random-force
small $o/fig2.2 ledger run-ledger
small $o/fig2.7 landscape_path fig2.7-below-the-surface
small $o/fig2.7 landscape_path_single fig2.7c-single-beam
small $o/h1 p_traverse fig3.1-h1-p-traverse
for g in 9 10 11; do small $o/h2-figures "trajectories_g$(printf %03d $g)" "fig3.2-g$g"; done
for g in 1 2; do small $o/h2-figures "landscape_g$(printf %03d $g)" "fig3.3-g$g"; done
small $o/fig3.4a traversal_vs_beams_0_stiffness fig3.4a
small $o/fig3.4b traversal_vs_effects_random_force_magnitude fig3.4b
small $o/c-track-20 lattice_g000 fig3.5-c-track-20
small $o/c-track-protocols/world lattice_g000 fig3.5-c-track-200
small $o/c-track-protocols final_locations_g000 c-track-protocols
small $o/c-track-backends final_locations_g000 c-track-backends
small $o/accuracy accuracy accuracy
small $o/h1-24-9N survival survival_h1_9N
small $o/essay essay essay
small $o/landscape landscape_beam landscape_beam
small $o/landscape landscape_total landscape_total
small $o/landscape landscape_top landscape_top
small $o/landscape-500-250 landscape_beam landscape_beam_500_250
small $o/landscape-100-500 landscape_top landscape_top_100_500
ls -l "$d"
