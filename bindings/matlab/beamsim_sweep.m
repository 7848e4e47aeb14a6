%BEAMSIM_SWEEP Every trial of an experiment, as `beamsim sweep` runs them (a MEX function).
%   S = BEAMSIM_SWEEP(EXPERIMENT, NAME, VALUE, ...) runs every trial of
%   every group of the experiment file and holds the results in memory as
%   columns.
%
%   Names:
%     'trials'       trials per group, instead of the file's
%     'seed'         the experiment's seed instead of the file's
%     'threads'      threads to use (default: all cores; the results do not
%                    depend on it)
%     'backend'      a physics backend (beamsim backends lists them)
%     'backend_opt'  {KEY, VALUE, ...}, the backend's options
%     'set'          {KEY, VALUE, ...}, scene keys set as by --set
%     'grid'         {KEY, VALUES, ...}, the experiment's grid axes
%     'overlap'      true: each trial's overlap_max
%
%   S.groups is a struct array, one element per group, with summary.json's
%   fields (its group field from 1). S.trials is a struct of n x 1 columns,
%   one per trials.csv column, at full precision: numbers as doubles (group
%   and trial from 1; an empty field of the file is NaN); each text column
%   (outcome, type, location, path, a grid axis of text) as codes into its
%   labels, S.labels.COLUMN: categorical arrays in MATLAB, the codes
%   themselves in Octave, where S.labels.outcome(S.trials.outcome) is the
%   text. A sweep whose columns would not fit in the memory available is
%   refused before it runs.
%
%   Example:
%     s = beamsim_sweep('configs/thesis/h1_symmetric.yaml', 'trials', 20);
%     [s.groups.p_traverse]
%
%   See also BEAMSIM_RUN, BEAMSIM_LOAD.
