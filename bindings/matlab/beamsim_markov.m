%BEAMSIM_MARKOV The Markov chain of a gate lattice (a MEX function).
%   B = BEAMSIM_MARKOV('build', EXPERIMENT, 'out', DIR, NAME, VALUE, ...)
%   builds what the lattices of EXPERIMENT are predicted from into DIR, as
%   `beamsim markov build` does (the same files, byte for byte): by default
%   the nearest-neighbour walks' training fields, one per gate kind of a
%   lattice's physics; with 'method', 'maps' (or any of the maps' names
%   below) the single-gate maps. Those already in DIR with the same key are
%   reused.
%
%   P = BEAMSIM_MARKOV('predict', SCENE, 'map', DIR, NAME, VALUE, ...)
%   predicts the lattice of the scene file from the build in DIR (walks
%   over its training fields, or the chain of its maps), as `beamsim
%   markov predict --json` does.
%
%   V = BEAMSIM_MARKOV('validate', EXPERIMENT, 'map', DIR, 'out', OUT, ...)
%   simulates every group of EXPERIMENT directly and against the chain, as
%   `beamsim markov validate` does, writing OUT's files.
%
%   build's names:
%     'out'          the directory (required)
%     'method'       'nearest' (the default): the walks' training fields;
%                    'maps': the maps (implied by 'trials', 'start_trials',
%                    'after_start', 'after_trials', 'crossings',
%                    'per_crossing', 'bins', 'vmax', 'entries')
%     'k'            the walks: each step from the k nearest visits
%                    (default 20)
%     'trials'       single gates per entry bin (default 50)
%     'start_trials' single gates of the start bin (default 16000, or
%                    'trials' with self or flow entries)
%     'after_start'  1 (default): each start trial that leaves into a gate
%                    goes on there from its exact state, and the chain
%                    takes the first two gates from those; 0: entry bins
%                    from the start on (0 with self or flow entries)
%     'after_trials' the first start trials continued there (default
%                    8000; the others take the continuations of those
%                    that entered the same gate); 0: every start trial
%     'train'        trials of each training field, a 21 x 21 field of the
%                    lattice's gate kinds at random (the walks' default
%                    10000); maps: the field whose gate entries the bins'
%                    states are drawn from (default 4000; run only when a
%                    map is built); 0: states uniform in each bin
%     'crossings'    1 (default, with a training field): each bin counts
%                    the training field's own crossings of the map's gate
%                    kind entered in it, topped up with single gates as
%                    'per_crossing' says; 0: 'trials' single gates a bin,
%                    from the field's entries
%     'per_crossing' single gates a bin is topped up to for each crossing
%                    that entered it (as for one where none did), at most
%                    'trials' (default 5); 0: every bin topped up to 'trials'
%     'bins'         [P S D], bins of position, speed and direction
%                    (default [14 6 13])
%     'vmax'         m/s, the top of the speed bins (default: 40, or F_prop/M x 40/7 s
%                    where that is more)
%     'entries'      gate_entries.csv paths (a text or a cell of texts), or
%                    'self', 'self:N', 'flow', 'flow:N' (docs/markov.md)
%     'seed', 'threads', 'backend', 'backend_opt', 'set', 'grid'
%                    as for BEAMSIM_SWEEP
%   B.maps is a struct array, one map (or training field) each: group
%   (from 1), k ([left right], N m/rad), key (its files' name, map_HASH or
%   visits_HASH), how ('built' or 'reused'); B.method ('nearest' or
%   'maps'), B.built, B.reused, B.cpu_seconds, B.bins, B.trials, B.visits,
%   B.run, B.scope (where maps of this method were measured to fall short
%   on layouts they were not built on; '' for the walks).
%
%   P = BEAMSIM_MARKOV('predict', SCENE, 'visits', DIR, NAME, VALUE, ...)
%   and V = BEAMSIM_MARKOV('validate', EXPERIMENT, 'visits', DIR, 'out',
%   OUT, ...) predict by nearest-neighbour walks over the visits of
%   training fields kept in DIR (those missing run there first), as
%   `beamsim markov predict --visits DIR` and `validate --visits DIR` do.
%
%   predict's names:
%     'map'          the directory of a build (or 'visits')
%     'visits'       the visits directory (or 'map')
%     'set'          {KEY, VALUE, ...}, scene keys set as by --set
%     'tol'          the probability left in the field at which the
%                    solution stops, in (0, 1) (default: the maps' sampling
%                    tolerance)
%     'gates'        true: the distribution of gates visited (default: with
%                    'out' only)
%     'walks'        the nearest-neighbour walks (default 200000); with the
%                    maps, walks of the semi-Markov chain (default 100000;
%                    0: none)
%     'out'          a directory: also write the program's files there
%     'overwrite'    true: replace the result 'out' holds
%     'k', 'train', 'seed', 'threads'
%                    with 'visits': each step from the k nearest visits
%                    (default 20), trials of each training field (default
%                    10000), the fields' and the walks' seed, threads;
%                    with a 'map' of the walks: 'threads'
%   P holds what `markov predict --json` prints (P.totals, P.locations,
%   P.p_gates, P.mean_gates, P.at_duration, ...), and P.p_time (time bins
%   x 3: end, side, stuck), P.time_bin (s) and P.p_loc_time.
%
%   validate's names: 'out' (required), 'map' (of the walks: then 'walks')
%   or 'visits' (then 'k', 'train', 'walks' as predict's), 'trials', 'seed', 'threads', 'set',
%   'grid', 'bootstrap', 'resume', 'overwrite'. V is validate.json
%   (V.checks: group from 1, protocol, tv, tv_sampling, ...).
%
%   Example:
%     beamsim_markov('build', 'configs/markov/c_track.yaml', 'out', 'maps', ...
%                    'trials', 20, 'bins', [2 2 1]);
%     p = beamsim_markov('predict', 'configs/lattice/c_track.yaml', 'map', 'maps');
%     p.totals
%
%   See also BEAMSIM_SWEEP, BEAMSIM_LOAD.
