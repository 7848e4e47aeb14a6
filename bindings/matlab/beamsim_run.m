%BEAMSIM_RUN One trial of beamsim, as `beamsim run` runs it (a MEX function).
%   R = BEAMSIM_RUN(ARG, NAME, VALUE, ...) runs one trial. ARG is a scene
%   file, an experiment file, or the output directory of a sweep or a
%   comparison (the trial it stored is run again, bit for bit).
%
%   Names:
%     'seed'         the experiment's seed instead of the file's
%     'group'        the group, from 1 (trials.csv's group plus 1)
%     'trial'        the trial, from 1 (trials.csv's trial plus 1)
%     'backend'      a physics backend (beamsim backends lists them), or a
%                    stored comparison's side by its label
%     'backend_opt'  {KEY, VALUE, ...}, the backend's options
%     'set'          {KEY, VALUE, ...}, scene keys set as by --set
%     'grid'         {KEY, VALUES, ...}, an experiment's grid axes
%     'trajectory'   true: also the recorded rows
%     'stride'       record every stride-th step
%
%   R holds what `beamsim run --json` prints: the outcome, its type, the
%   steps and time to it, the end state, the beams' peaks, the energy
%   ledger. With 'trajectory', R.trajectory holds the columns of run
%   --trajectory's CSV and R.ledger_rows those of run --out's ledger.csv,
%   each a column vector.
%
%   Example:
%     r = beamsim_run('configs/thesis/gate.yaml', 'trajectory', true);
%     plot(r.trajectory.x, r.trajectory.y)
%
%   See also BEAMSIM_SWEEP, BEAMSIM_LANDSCAPE, BEAMSIM_LOAD.
