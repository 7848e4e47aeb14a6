% beamsim_markov (bindings/matlab) against the program's `beamsim markov
% build`, `predict --json` and `validate` for the same inputs: the same maps
% byte for byte, the same prediction and validation (but for the times
% measured), and the program's refusals. Small maps (3 single gates a bin,
% 2 x 2 x 1 bins) on the C-track.
%   octave --no-gui --no-window-system -q test_markov.m BUILD SOURCE BEAMSIM TMP
% Exits 1 naming the first difference.
1;

% The files of a map directory but for the CPU times (.cost) and the
% manifest, which lists their sizes: names and contents.
function [names, texts] = map_files(dir_)
  d = dir(dir_);
  names = sort({d(~[d.isdir]).name});
  names = names(cellfun(@isempty, regexp(names, '(\.cost|manifest\.json)$', 'once')));
  texts = cellfun(@(n) fileread(fullfile(dir_, n)), names, 'UniformOutput', false);
end

% s without the fields that hold times measured (and the MEX function's
% arrays beside the JSON).
function s = untimed(s)
  drop = {'predict_seconds', 'predict_cpu_seconds', 'sim_cpu_seconds', 'speedup', ...
          'break_even_lattices', 'map_cpu_seconds', 'map_dir', 'p_time', 'time_bin', ...
          'p_loc_time'};
  if isstruct(s)
    s = rmfield(s, intersect(fieldnames(s), drop));
    for i = 1:numel(s)
      for f = fieldnames(s)'
        s(i).(f{1}) = untimed(s(i).(f{1}));
      end
    end
  end
end

source(fullfile(fileparts(mfilename('fullpath')), 'mex_helpers.m'));
[build, source, exe, tmp] = test_setup();
experiment = fullfile(source, 'configs', 'markov', 'c_track.yaml');
scene = fullfile(source, 'configs', 'lattice', 'c_track.yaml');
small = '--trials 3 --start-trials 7 --train 40 --bins 2,2,1 --threads 2 --seed 5';

% ---- build: the program's maps -------------------------------------------
mine = fullfile(tmp, 'maps_mex');
theirs = fullfile(tmp, 'maps_program');
b = beamsim_markov('build', experiment, 'out', mine, 'trials', 3, 'start_trials', 7, 'train', 40, 'bins', [2 2 1], ...
                   'threads', 2, 'seed', 5);
[out, err, status] = program(exe, tmp, sprintf('markov build %s %s --out %s', experiment, ...
                                               small, theirs));
check(status == 0, 'beamsim markov build: exit %d: %s', status, err);
keys = regexp(out, '^group [^\n]*(map_[0-9a-f]{16})', 'tokens', 'lineanchors');
keys = [keys{:}];
check(isequal({b.maps.key}, keys), 'maps %s, the program %s', strjoin({b.maps.key}, ' '), ...
      strjoin(keys, ' '));
check(all([b.maps.group] == 1) && b.built == numel(keys) && b.reused == 0 && b.bins == 17, ...
      'build: groups from 1, %d built, %d reused, %d bins', b.built, b.reused, b.bins);
[n1, t1] = map_files(mine);
[n2, t2] = map_files(theirs);
check(isequal(n1, n2) && isequal(t1, t2), 'the maps differ from the program''s: %s / %s', ...
      strjoin(n1, ' '), strjoin(n2, ' '));
check(any(~cellfun(@isempty, strfind(n1, '.after_'))), 'no gate after the start in %s', ...
      strjoin(n1, ' '));
check(strncmp(b.scope, 'maps with 40 training trials', 28) && ~isempty(strfind(err, ['note: ' b.scope])), ...
      'the scope ''%s'' is not the program''s note: %s', b.scope, err);
% 'after_start', 0 as --after-start 0 (no gate after the start), 'crossings', 0 as
% --crossings 0 (bins of single gates alone), 'per_crossing', 1 as --per-crossing 1 and
% 'after_trials', 3 as --after-trials 3 (the first 3 start trials continued)
variants = {'after_start', 0, '--after-start 0'; 'crossings', 0, '--crossings 0'; ...
            'per_crossing', 1, '--per-crossing 1'; 'after_trials', 3, '--after-trials 3'};
for i = 1:rows(variants)
  [name, value, option] = variants{i, :};
  mine0 = fullfile(tmp, ['maps_mex_' name]);
  theirs0 = fullfile(tmp, ['maps_program_' name]);
  beamsim_markov('build', experiment, 'out', mine0, 'trials', 3, 'start_trials', 7, 'train', 40, ...
                 'bins', [2 2 1], 'threads', 2, 'seed', 5, name, value);
  [out, err, status] = program(exe, tmp, sprintf('markov build %s %s %s --out %s', ...
                                                 experiment, small, option, theirs0));
  check(status == 0, 'beamsim markov build %s: exit %d: %s', option, status, err);
  [n3, t3] = map_files(mine0);
  [n4, t4] = map_files(theirs0);
  none_after = all(cellfun(@isempty, strfind(n3, '.after_')));
  first3 = any(~cellfun(@isempty, strfind(n3, '.first3.csv')));
  check(isequal(n3, n4) && isequal(t3, t4) && none_after == strcmp(name, 'after_start') && ...
        first3 == strcmp(name, 'after_trials'), ...
        '%s: %s / %s', option, strjoin(n3, ' '), strjoin(n4, ' '));
end
again = beamsim_markov('build', experiment, 'out', mine, 'trials', 3, 'start_trials', 7, 'train', 40, 'bins', [2 2 1], 'seed', 5);
check(again.reused == numel(keys) && again.built == 0, 'a build again: %d reused', again.reused);
printf('build: %d maps, the program''s bytes\n', numel(keys));

% ---- predict: the program's --json ---------------------------------------
for walks = {[], 0}
  extra = {};
  flag = '';
  if ~isempty(walks{1})
    extra = {'walks', walks{1}};
    flag = sprintf('--walks %d', walks{1});
  end
  [out, err, status] = program(exe, tmp, sprintf('markov predict %s --map %s --json %s', ...
                                                 scene, theirs, flag));
  check(status == 0, 'beamsim markov predict: exit %d: %s', status, err);
  want = jsondecode(out);
  p = beamsim_markov('predict', scene, 'map', mine, extra{:});
  check(isequal(untimed(p), untimed(want)), 'predict %s: not the program''s', flag);
  check(size(p.p_time, 2) == 3 && (isempty(walks{1}) == (size(p.p_time, 1) > 0)), ...
        'predict %s: p_time %d x %d', flag, size(p.p_time, 1), size(p.p_time, 2));
end
% the time bins sum to the walks' outcome at the duration
check(abs(sum(p.p_time(:)) - 1) < 1e-9 || isempty(p.p_time), 'p_time sums to %.17g', ...
      sum(p.p_time(:)));
p = beamsim_markov('predict', scene, 'map', mine, 'gates', true, 'tol', 1e-9, 'walks', 0);
[out, err, status] = program(exe, tmp, sprintf(['markov predict %s --map %s --json --gates ' ...
                                                '--tol 1e-9 --walks 0'], scene, theirs));
check(status == 0 && isequal(untimed(p), untimed(jsondecode(out))) && numel(p.p_gates) > 1, ...
      'predict --gates --tol 1e-9: not the program''s');
printf('predict: end %.4f, side %.4f, stuck %.4f, the program''s\n', p.totals.xEnd, ...
       p.totals.side, p.totals.stuck);

% ---- validate: the program's validate.json and validate.csv ---------------
vmine = fullfile(tmp, 'val_mex');
vtheirs = fullfile(tmp, 'val_program');
v = beamsim_markov('validate', experiment, 'map', mine, 'out', vmine, 'trials', 12, ...
                   'bootstrap', 30, 'threads', 2);
[out, err, status] = program(exe, tmp, sprintf(['markov validate %s --map %s --out %s ' ...
                                                '--trials 12 --bootstrap 30 --threads 2'], ...
                                               experiment, theirs, vtheirs));
check(status == 0, 'beamsim markov validate: exit %d: %s', status, err);
want = jsondecode(fileread(fullfile(vtheirs, 'validate.json')));
check([v.checks.group] == [want.checks.group] + 1, 'validate: groups not from 1');
v.checks = rmfield(v.checks, 'group');
want.checks = rmfield(want.checks, 'group');
check(isequal(untimed(v), untimed(want)), 'validate: validate.json not the program''s');
check(strcmp(fileread(fullfile(vmine, 'validate.csv')), ...
             fileread(fullfile(vtheirs, 'validate.csv'))), 'validate.csv not the program''s');
[id, msg] = raised(@beamsim_markov, 'validate', experiment, 'map', mine, 'out', vmine, ...
                   'trials', 12, 'bootstrap', 30);
check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, '''overwrite'', true')) && ...
      isempty(strfind(msg, '--overwrite')), 'a finished validation: %s %s', id, msg);
printf('validate: TV %.3f (essay), %.3f (world), the program''s\n', v.checks(1).tv, ...
       v.checks(2).tv);

% ---- nearest-neighbour walks: the program's --visits ------------------------
visits = fullfile(tmp, 'visits');
p = beamsim_markov('predict', scene, 'visits', visits, 'train', 200, 'walks', 2000, 'threads', 2);
[out, err, status] = program(exe, tmp, sprintf(['markov predict %s --visits %s --train 200 ' ...
                                                '--walks 2000 --threads 1 --json'], scene, visits));
check(status == 0, 'beamsim markov predict --visits: exit %d: %s', status, err);
want = jsondecode(out);
check(strcmp(p.solve, 'nearest') && p.fields_built > 0 && want.fields_built == 0 && ...
      isequal([p.locations.p], [want.locations.p]), 'predict --visits: not the program''s');
printf('predict --visits: end %.4f, the program''s\n', p.totals.xEnd);

% ---- the default build: the walks' training fields, as the program's -------
walks = fullfile(tmp, 'walks_mex');
walks_program = fullfile(tmp, 'walks_program');
b = beamsim_markov('build', experiment, 'out', walks, 'train', 60, 'threads', 2);
[out, err, status] = program(exe, tmp, sprintf('markov build %s --train 60 --out %s', ...
                                               experiment, walks_program));
check(status == 0, 'beamsim markov build (the walks): exit %d: %s', status, err);
check(strcmp(b.method, 'nearest') && b.visits > 0 && all(strncmp({b.maps.key}, 'visits_', 7)), ...
      'build: method %s, %d visits', b.method, b.visits);
[n1, t1] = map_files(walks);
[n2, t2] = map_files(walks_program);
check(isequal(n1, n2) && isequal(t1, t2), 'the training fields differ from the program''s: %s / %s', ...
      strjoin(n1, ' '), strjoin(n2, ' '));
p = beamsim_markov('predict', scene, 'map', walks, 'walks', 2000);
[out, err, status] = program(exe, tmp, sprintf('markov predict %s --map %s --walks 2000 --json', ...
                                               scene, walks_program));
check(status == 0, 'beamsim markov predict --map (the walks): exit %d: %s', status, err);
want = jsondecode(out);
check(strcmp(p.solve, 'nearest') && p.fields_built == 0 && ...
      isequal([p.locations.p], [want.locations.p]), 'predict over the build: not the program''s');
printf('build (the walks) and predict --map: end %.4f, the program''s\n', p.totals.xEnd);

% ---- refusals ---------------------------------------------------------------
h1 = fullfile(source, 'configs', 'thesis', 'h1_symmetric.yaml');
target = fullfile(tmp, 'refused');
[~, err, status] = program(exe, tmp, sprintf('markov build %s --out %s', h1, target));
[id, msg] = raised(@beamsim_markov, 'build', h1, 'out', target);
check(status == 2 && strcmp(id, 'beamsim:input'), 'not a lattice: %s, exit %d', id, status);
check_message('not a lattice', msg, err, 'beamsim_markov');
missing = fullfile(tmp, 'none');
[~, err, status] = program(exe, tmp, sprintf('markov predict %s --map %s', scene, missing));
[id, msg] = raised(@beamsim_markov, 'predict', scene, 'map', missing);
check(status == 2 && strcmp(id, 'beamsim:input'), 'no maps: %s, exit %d', id, status);
check_message('no maps', msg, err, 'beamsim_markov');
bad = {{'build', experiment, 'out', target, 'bins', [2 0 1]}, '''bins'': expected [P S D]';
       {'build', experiment, 'out', target, 'entries', 'self:9'}, 'entries self:9: expected';
       {'predict', scene, 'map', mine, 'tol', 2}, '''tol'' 2: expected the probability';
       {'predict', scene, 'map', mine, 'trials', 3}, '''trials'': not an argument of ''predict''';
       {'predict', scene}, 'expected one of ''map'' (the map directory) and ''visits''';
       {'predict', scene, 'map', mine, 'k', 3}, '''k'': for ''visits'' only';
       {'build', experiment, 'out', target, 'method', 'maps', 'k', 3}, 'k is for the nearest';
       {'build', experiment, 'out', target, 'method', 'nearest', 'bins', [2 2 1]}, ...
       'bins is for method maps';
       {'bild', scene}, '''bild'': expected ''build'', ''predict'' or ''validate'''};
for k = 1:size(bad, 1)
  [id, msg] = raised(@beamsim_markov, bad{k, 1}{:});
  check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, bad{k, 2})), ...
        'refusal %d: %s %s', k, id, msg);
end
check(~exist(target, 'dir'), '%s written by a refused call', target);
pred = fullfile(tmp, 'pred');
beamsim_markov('predict', scene, 'map', mine, 'walks', 0, 'out', pred);
[id, msg] = raised(@beamsim_markov, 'predict', scene, 'map', mine, 'walks', 0, 'out', pred);
check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, '''overwrite'', true')), ...
      'a finished prediction: %s %s', id, msg);
beamsim_markov('predict', scene, 'map', mine, 'walks', 0, 'out', pred, 'overwrite', true);
printf('refusals: %d, the program''s words\n', size(bad, 1) + 3);
