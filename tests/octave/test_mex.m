% The MEX functions (bindings/matlab) against the program's own numbers for
% the same trial, sweep and landscape, and their errors against the
% program's messages. One Octave process (its start-up is the slow part):
%   octave --no-gui --no-window-system -q test_mex.m BUILD SOURCE BEAMSIM TMP
% Exits 1 naming the first difference.
1;

% The lines of a CSV file: header names and the fields of every row.
function [names, cols] = csv_columns(file)
  text = fileread(file);
  lines = strsplit(strtrim(text), "\n");
  names = strsplit(lines{1}, ',');
  rows = regexp(lines(2:end), ',', 'split');
  cells = vertcat(rows{:});
  cols = cell(1, numel(names));
  for j = 1:numel(names)
    cols{j} = cells(:, j);
  end
end

% Values v written as the program writes them (printf format fmt, NaN as an
% empty field) are the file's fields, text for text.
function check_column(what, name, v, fields, fmt)
  if iscell(v)
    same = isequal(v(:), fields(:));
    bad = find(~strcmp(v(:), fields(:)), 1);
    check(same, '%s: column %s row %d: %s, the file %s', what, name, bad, v{bad}, fields{bad});
    return;
  end
  text = strsplit(sprintf([fmt "\n"], v), "\n");
  text = text(1:end - 1)';
  text(isnan(v)) = {''};
  bad = find(~strcmp(text, fields(:)), 1);
  check(isempty(bad), '%s: column %s row %d: %s, the file %s', what, name, bad, ...
        text{min(bad, end)}, fields{min(bad, end)});
end

source(fullfile(fileparts(mfilename('fullpath')), 'mex_helpers.m'));
[build, source, exe, tmp] = test_setup();
gate = fullfile(source, 'configs', 'thesis', 'gate.yaml');
h1 = fullfile(source, 'configs', 'thesis', 'h1_symmetric.yaml');
h2 = fullfile(source, 'configs', 'thesis', 'h2_asymmetric.yaml');

% ---- one trial of a scene: run --json and run --out's CSVs -------------
rundir = fullfile(tmp, 'run');
[out, err, status] = program(exe, tmp, sprintf('run %s --seed 3 --trial 2 --json --out %s', ...
                                               gate, rundir));
check(status == 0, 'beamsim run: exit %d: %s', status, err);
cli = jsondecode(out);
r = beamsim_run(gate, 'seed', 3, 'trial', 3, 'trajectory', true);
check(r.group == 1 && r.trial == 3, 'group and trial from 1: %d, %d', r.group, r.trial);
% (printf takes a uint64 beyond 2^63 as a double: in two halves)
hi = idivide(r.mixed_seed, uint64(1e10));
seed = sprintf('%d%010d', hi, r.mixed_seed - hi * uint64(1e10));
seed = regexprep(seed, '^0+(?=.)', '');
check(strcmp(seed, cli.mixed_seed), 'mixed seed %s, the program %s', seed, cli.mixed_seed);
for f = {'outcome', 'type'}
  check(strcmp(r.(f{1}), cli.(f{1})), '%s: %s, the program %s', f{1}, r.(f{1}), cli.(f{1}));
end
for f = {'steps', 'steps_run', 'draws', 't_end', 'x_end', 'y_end', 'vx_end', 'heading_end', ...
         'angular_velocity_end', 'turn_end', 'turn_max', 'overlap_max', 'in_contact_end', ...
         'reset_overlaps'}
  check(json_same(r.(f{1}), cli.(f{1})), '%s: %.17g, the program %.17g', f{1}, r.(f{1}), ...
        cli.(f{1}));
end
check(json_same(r.max_theta, cli.max_theta), 'max_theta differs');
for f = fieldnames(cli.ledger)'
  check(json_same(r.ledger.(f{1}), cli.ledger.(f{1})), 'ledger.%s: %.17g, the program %.17g', f{1}, ...
        r.ledger.(f{1}), cli.ledger.(f{1}));
end
% The trajectory and the ledger over time, written as the program writes
% them, are its files field for field.
tables = {'trajectory', 'ledger_rows'; 'trajectory.csv', 'ledger.csv'};
for k = 1:2
  [names, cols] = csv_columns(fullfile(rundir, tables{2, k}));
  mine = r.(tables{1, k});
  check(isequal(fieldnames(mine)', names), '%s: columns %s, the file %s', tables{1, k}, ...
        strjoin(fieldnames(mine)', ','), strjoin(names, ','));
  for j = 1:numel(names)
    fmt = '%.10g';
    if strcmp(names{j}, 't')
      fmt = '%.6f';
    elseif strncmp(names{j}, 'contact', 7) && ~strcmp(names{j}, 'contact')
      fmt = '%d';
    end
    check_column(tables{1, k}, names{j}, mine.(names{j}), cols{j}, fmt);
  end
end
printf('run: %s, %d steps, %d trajectory rows: the program''s numbers\n', r.outcome, r.steps, ...
       numel(r.trajectory.t));

% A capsule that turns (Box2D): the trajectory ends with heading and
% angular_velocity, in the MEX function as in the program's file.
capsule = fullfile(tmp, 'capsule.yaml');
text = strrep(fileread(gate), 'body:      { mass: 1.0, radius: 10.0,', ...
              'body:      { mass: 1.0, radius: 6.0, shape: capsule, length: 10,');
check(~isempty(strfind(text, 'capsule')), 'the capsule scene');
fid = fopen(capsule, 'w');
fputs(fid, text);
fclose(fid);
capdir = fullfile(tmp, 'run_capsule');
[out, err, status] = program(exe, tmp, sprintf('run %s --backend box2d --out %s', capsule, ...
                                               capdir));
check(status == 0, 'beamsim run capsule: exit %d: %s', status, err);
rc = beamsim_run(capsule, 'backend', 'box2d', 'trajectory', true);
[names, cols] = csv_columns(fullfile(capdir, 'trajectory.csv'));
check(isequal(fieldnames(rc.trajectory)', names) && strcmp(names{end}, 'angular_velocity'), ...
      'capsule trajectory: columns %s, the file %s', strjoin(fieldnames(rc.trajectory)', ','), ...
      strjoin(names, ','));
for j = 1:numel(names)
  fmt = '%.10g';
  if strcmp(names{j}, 't')
    fmt = '%.6f';
  elseif strncmp(names{j}, 'contact', 7)
    fmt = '%d';
  end
  check_column('capsule trajectory', names{j}, rc.trajectory.(names{j}), cols{j}, fmt);
end
% How far it turned: the program's numbers (run --json), and a turn.
[out, err, status] = program(exe, tmp, sprintf('run %s --backend box2d --json', capsule));
check(status == 0, 'beamsim run capsule --json: exit %d: %s', status, err);
cli = jsondecode(out);
turn = {'heading_end', 'angular_velocity_end', 'turn_end', 'turn_max'};
for f = turn
  check(json_same(rc.(f{1}), cli.(f{1})), 'capsule %s: %.17g, the program %.17g', f{1}, ...
        rc.(f{1}), cli.(f{1}));
end
check(rc.turn_max > 0.01 && rc.turn_max >= abs(rc.turn_end), 'capsule: turned %g, at most %g', ...
      rc.turn_end, rc.turn_max);
% A sweep of it, its body turning in group 1 and not in group 2: the
% groups' turn as summary.json's, which has none for group 2.
capexp = fullfile(tmp, 'capsule_exp.yaml');
fid = fopen(capexp, 'w');
fprintf(fid, ['scene: %s\ntrials: 3\nseed: 2\nset:\n  integration.max_steps: 1500\n' ...
              'grid:\n  body.rotates: [true, false]\n'], capsule);
fclose(fid);
capsweep = fullfile(tmp, 'capsule_sweep');
[~, err, status] = program(exe, tmp, sprintf('sweep %s --backend box2d --quiet --out %s', ...
                                             capexp, capsweep));
check(status == 0, 'beamsim sweep capsule: exit %d: %s', status, err);
cs = beamsim_sweep(capexp, 'backend', 'box2d');
summary = jsondecode(fileread(fullfile(capsweep, 'summary.json')));
groups = summary.groups;
if ~iscell(groups)
  groups = num2cell(groups);
end
for f = {'turn_end_mean', 'turn_end_mean_abs', 'turn_end_max_abs', 'turn_max'}
  check(json_same(cs.groups(1).(f{1}), groups{1}.(f{1})), ...
        'capsule group 1 %s: %.17g, summary.json %.17g', f{1}, cs.groups(1).(f{1}), ...
        groups{1}.(f{1}));
  check(isempty(cs.groups(2).(f{1})) && ~isfield(groups{2}, f{1}), ...
        'capsule group 2 (not turning) has %s', f{1});
end
check(cs.groups(1).turn_max > 0 && ...
      isequal(cs.groups(1).turn_max, max(cs.trials.turn_max(cs.trials.group == 1))), ...
      'capsule group 1: largest turn %g', cs.groups(1).turn_max);
printf('capsule: turned %.4g rad (at most %.4g), its sweep''s groups as summary.json''s\n', ...
       rc.turn_end, rc.turn_max);

% ---- a trial of an experiment's group, with --set, on Box2D ------------
[out, err, status] = program(exe, tmp, sprintf(['run %s --group 10 --trial 3 --backend box2d ' ...
                                                '--set body.mass=1.5 --json'], h2));
check(status == 0, 'beamsim run (experiment): exit %d: %s', status, err);
cli = jsondecode(out);
r = beamsim_run(h2, 'group', 11, 'trial', 4, 'backend', 'box2d', 'set', {'body.mass', 1.5});
check(strcmp(r.outcome, cli.outcome) && r.steps == cli.steps && json_same(r.t_end, cli.t_end) && ...
      json_same(r.x_end, cli.x_end) && json_same(r.y_end, cli.y_end) && ...
      json_same(r.ledger.e_end, cli.ledger.e_end), ...
      'experiment trial: %s %d %.17g, the program %s %d %.17g', r.outcome, r.steps, r.t_end, ...
      cli.outcome, cli.steps, cli.t_end);
check(strcmp(r.backend, 'box2d') && strcmp(r.grid, ['effects.propulsion.force=7, ' ...
      'effects.random_force.magnitude=20, beams.0.stiffness=150']), 'grid line: %s', r.grid);
printf('run of an experiment: group 11, trial 4 on box2d: the program''s numbers\n');

% ---- a sweep with --set and --grid: trials.csv and summary.json ---------
sweepdir = fullfile(tmp, 'sweep');
[out, err, status] = program(exe, tmp, sprintf(['sweep %s --trials 10 --threads 2 ' ...
    '--set contact.restitution=0.7 --grid effects.random_force.magnitude=10,30 --quiet --out %s'], ...
    h1, sweepdir));
check(status == 0, 'beamsim sweep: exit %d: %s', status, err);
opts = {'trials', 10, 'set', {'contact.restitution', 0.7}, ...
        'grid', {'effects.random_force.magnitude', [10 30]}};
s = beamsim_sweep(h1, opts{:}, 'threads', 2);
[names, cols] = csv_columns(fullfile(sweepdir, 'trials.csv'));
fields = fieldnames(s.trials)';
check(numel(fields) == numel(names), 'trials: %d columns, trials.csv %d', numel(fields), ...
      numel(names));
check(isequal(sort(fieldnames(s.labels)), sort({'outcome'; 'type'; 'location'; 'path'})) && ...
      isequal(s.labels.outcome', {'traversed', 'side_exit', 'stuck', 'unstable'}) && ...
      isequal(s.labels.type', {'none', 'left', 'right'}), 'labels: %s', ...
      strjoin(fieldnames(s.labels)', ', '));
for j = 1:numel(names)
  f = regexprep(names{j}, '[^A-Za-z0-9_]', '_');
  check(strcmp(fields{j}, f), 'trials column %d: %s, trials.csv %s', j, fields{j}, names{j});
  v = s.trials.(f);
  if isfield(s.labels, f)
    % a text column: a code a row (the narrowest unsigned class) into its labels
    check(any(strcmp(class(v), {'uint8', 'uint16', 'uint32'})) && iscellstr(s.labels.(f)), ...
          'trials column %s: codes of class %s', f, class(v));
    v = s.labels.(f)(v);
  else
    check(isa(v, 'double'), 'trials column %s: class %s', f, class(v));
  end
  fmt = '%.10g';
  if any(strcmp(f, {'group', 'trial'}))
    v = v - 1;  % trials.csv counts from 0
    fmt = '%d';
  end
  check_column('sweep', names{j}, v, cols{j}, fmt);
end
summary = jsondecode(fileread(fullfile(sweepdir, 'summary.json')));
check(numel(s.groups) == numel(summary.groups), 'groups: %d, summary.json %d', ...
      numel(s.groups), numel(summary.groups));
for g = 1:numel(s.groups)
  a = s.groups(g);
  b = summary.groups(g);
  if iscell(summary.groups)
    b = summary.groups{g};
  end
  for f = {'trials', 'traversed', 'side_exit', 'stuck', 'left', 'right', 'p_traverse', ...
           'stuck_in_contact', 'landscape_left', 'landscape_right', 'steps', 'unstable'}
    check(json_same(a.(f{1}), b.(f{1})), 'group %d %s: %g, summary.json %g', g, f{1}, a.(f{1}), b.(f{1}));
  end
  check(json_same(a.ci95, b.ci95) && isequal(a.params, b.params) && ...
        a.deterministic == b.deterministic, 'group %d: interval or params differ', g);
end
one = beamsim_sweep(h1, opts{:}, 'threads', 1);
check(isequaln(one.trials, s.trials) && isequaln(rmfield(one.groups, 'steps'), ...
      rmfield(s.groups, 'steps')), 'the sweep on 1 and 2 threads differs');
printf('sweep: %d groups x %d trials: trials.csv and summary.json, 1 and 2 threads the same\n', ...
       numel(s.groups), s.trials_per_group);

% ---- a grid axis of text: codes into its values, trials.csv's column ----
textexp = fullfile(tmp, 'text_axis.yaml');
fid = fopen(textexp, 'w');
fprintf(fid, ['scene: %s\ntrials: 2\nseed: 4\nset:\n  integration.max_steps: 30\n' ...
              'grid:\n  name: [gate_b, gate_a]\n  effects.propulsion.force: [7, 9]\n'], gate);
fclose(fid);
textdir = fullfile(tmp, 'text_axis');
[~, err, status] = program(exe, tmp, sprintf('sweep %s --quiet --out %s', textexp, textdir));
check(status == 0, 'beamsim sweep (text axis): exit %d: %s', status, err);
t = beamsim_sweep(textexp);
[names, cols] = csv_columns(fullfile(textdir, 'trials.csv'));
check(isa(t.trials.name, 'uint8') && isequal(t.labels.name', {'gate_b', 'gate_a'}), ...
      'text axis: class %s', class(t.trials.name));
check_column('text axis', 'name', t.labels.name(t.trials.name), cols{strcmp(names, 'name')}, '');
printf('a text grid axis: %d codes into its 2 values, trials.csv''s column\n', numel(t.trials.name));

% ---- a trial of the stored sweep, and what a stored run refuses ---------
outcome = s.labels.outcome(s.trials.outcome);
k = find(strcmp(outcome, 'traversed'), 1);
if isempty(k)
  k = numel(s.trials.group);
end
r = beamsim_run(sweepdir, 'group', s.trials.group(k), 'trial', s.trials.trial(k));
check(strcmp(r.outcome, outcome{k}) && r.t_end == s.trials.t_end(k) && ...
      r.x_end == s.trials.x_end(k) && r.y_end == s.trials.y_end(k), ...
      'the stored trial, group %d trial %d, replayed differs', s.trials.group(k), s.trials.trial(k));
[~, err, status] = program(exe, tmp, sprintf('run %s --group 1 --trial 1 --seed 3', sweepdir));
[id, msg] = raised(@beamsim_run, sweepdir, 'group', 2, 'trial', 2, 'seed', 3);
check(status == 2 && strcmp(id, 'beamsim:input'), 'a seed for a stored run: %s, exit %d', id, status);
check_message('a seed for a stored run', msg, err, 'beamsim_run');
printf('stored run: group %d, trial %d replayed as stored\n', r.group, r.trial);

% ---- beamsim_load of the sweep's directory ------------------------------
d = beamsim_load(sweepdir);
check(isequal(d.trials.group, s.trials.group) && isequal(d.trials.trial, s.trials.trial) && ...
      isequal(d.trials.outcome, outcome), 'beamsim_load: trials differ');
rel = abs(d.trials.t_end - s.trials.t_end) ./ max(abs(s.trials.t_end), 1);
check(max(rel) < 1e-9, 'beamsim_load: t_end off by %g', max(rel));
check(numel(d.summary.groups) == numel(s.groups) && isfield(d, 'run') && isfield(d, 'manifest'), ...
      'beamsim_load: summary.json, run.json or manifest.json missing');
printf('beamsim_load: %d trials as the sweep returned them (to trials.csv''s 10 digits)\n', ...
       numel(d.trials.group));

% A table with quoted fields, an empty field and nan; a short line refused.
file = fullfile(tmp, 'quoted.csv');
fid = fopen(file, 'w');
fprintf(fid, 'group,"a,b",c\n0,"x, ""y""",1.5\n1,z,\n2,"",nan\n');
fclose(fid);
t = beamsim_load(tmp).quoted;
check(isequal(t.group, [1; 2; 3]) && isequal(t.a_b, {'x, "y"'; 'z'; ''}) && ...
      isequaln(t.c, [1.5; NaN; NaN]), 'quoted.csv read wrong');
fid = fopen(file, 'a');
fprintf(fid, '3,w\n');
fclose(fid);
[id, msg] = raised(@beamsim_load, tmp);
check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, 'quoted.csv:5: expected 3 fields, got 2')), ...
      'a short line: %s %s', id, msg);
delete(file);
printf('beamsim_load: quoted fields, empty fields and nan; a short line refused\n');

% Regression: beamsim_read_csv kept the text before a NUL, one of two
% columns that become one field name (a.b and a_b, or names alike in their
% first 63 characters, MATLAB's longest), and read anything it was given
% (a directory as a read error, /dev/zero until memory ran out). Each is
% refused naming the file and what is wrong, as the library reads a table.
csvdir = fullfile(tmp, 'csv');
mkdir(csvdir);
long = repmat('x', 1, 63);
bad = {'nul.csv', ['a,b' "\n" '1,2' char(0) 'junk' "\n" '3,4' "\n"], ...
       'nul.csv:2:4: expected text, got a NUL byte';
       'dup.csv', ['a.b,c,a_b' "\n" '1,2,3' "\n"], ...
       'dup.csv:1: columns 1 (a.b) and 3 (a_b) both become the field a_b ';
       'long.csv', [long 'yy,' long 'zz' "\n" '1,2' "\n"], ...
       ['long.csv:1: columns 1 (' long 'yy) and 2 (' long 'zz) both become the field ' long ' ']};
for k = 1:size(bad, 1)
  f = fullfile(csvdir, bad{k, 1});
  fid = fopen(f, 'w');
  fwrite(fid, bad{k, 2});
  fclose(fid);
  [id, msg] = raised(@beamsim_read_csv, f);
  check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, bad{k, 3})), '%s: %s %s', ...
        bad{k, 1}, id, msg);
  delete(f);
end
% Names apart within 63 characters stay apart.
f = fullfile(csvdir, 'longok.csv');
fid = fopen(f, 'w');
fprintf(fid, '%s,%s\n1,2\n', [long(1:62) 'a' 'tail'], [long(1:62) 'b' 'tail']);
fclose(fid);
t = beamsim_read_csv(f);
names = fieldnames(t)';
check(isequal(names, {[long(1:62) 'a'], [long(1:62) 'b']}) && t.(names{1}) == 1 && ...
      t.(names{2}) == 2, 'long names: %s', strjoin(names, ','));
delete(f);
% Not a regular file, refused at once: a directory, a device; and a file
% over the bound, 16 GiB (sparse: no byte of it is written or read).
big = fullfile(csvdir, 'big.csv');
check(system(sprintf('truncate -s 17179869185 %s', big)) == 0, 'truncate %s', big);
refused = {csvdir, 'expected a CSV file, got a directory';
           '/dev/zero', 'expected a CSV file, got a character device';
           big, 'expected a file of at most 17179869184 bytes, got more'};
for k = 1:size(refused, 1)
  [id, msg] = raised(@beamsim_read_csv, refused{k, 1});
  check(strcmp(id, 'beamsim:input') && ...
        ~isempty(strfind(msg, [refused{k, 1} ': ' refused{k, 2}])), '%s: %s %s', ...
        refused{k, 1}, id, msg);
end
delete(big);
printf(['beamsim_read_csv: a NUL, columns of one field name, a directory, a device and ' ...
        '16 GiB refused\n']);

% ---- the landscape ------------------------------------------------------
landdir = fullfile(tmp, 'landscape');
[out, err, status] = program(exe, tmp, sprintf('landscape %s --resolution 0.5 --json --out %s', ...
                                               gate, landdir));
check(status == 0, 'beamsim landscape: exit %d: %s', status, err);
cli = jsondecode(out);
l = beamsim_landscape(gate, 'resolution', 0.5);
p = l.barriers.lowest;
q = cli.lowest_pass;
check(strcmp(p.kind, q.kind) && p.beam == q.crossed && json_same(p.x, q.x) && ...
      json_same(p.y, q.y) && json_same(p.height, q.height) && json_same(p.e_total, q.e_total), ...
      'lowest pass: %s beam %d height %.17g, the program %s beam %d height %.17g', p.kind, ...
      p.beam, p.height, q.kind, q.crossed, q.height);
check(numel(l.x) == cli.grid.nx && numel(l.y) == cli.grid.ny, 'grid %d x %d, the program %d x %d', ...
      numel(l.x), numel(l.y), cli.grid.nx, cli.grid.ny);
[names, cols] = csv_columns(fullfile(landdir, 'landscape.csv'));
% landscape.csv: a row per point, x fastest.
check_column('landscape', 'e_total', reshape(l.e_total', [], 1), cols{strcmp(names, 'e_total')}, ...
             '%.10g');
check_column('landscape', 'theta2', reshape(l.theta(:, :, 2)', [], 1), ...
             cols{strcmp(names, 'theta2')}, '%.10g');
printf('landscape: %d x %d points and the lowest pass (%.2f J) as the program''s\n', ...
       numel(l.x), numel(l.y), p.height);
% Into the program's finished landscape: refused as the program refuses it
% (below, with the errors), replaced with 'overwrite'.
l2 = beamsim_landscape(gate, 'resolution', 2, 'out', landdir, 'overwrite', true);
[names, cols] = csv_columns(fullfile(landdir, 'landscape.csv'));
check(numel(cols{1}) == numel(l2.x) * numel(l2.y), 'overwrite: %d rows for %d x %d points', ...
      numel(cols{1}), numel(l2.x), numel(l2.y));

% ---- unstable trials: an ordinary result, said as the program says it ---
stiff = fullfile(source, 'configs', 'hard', 'stiff_beam_sweep.yaml');
[~, err, status] = program(exe, tmp, sprintf(['run %s --group 1 --backend box2d ' ...
                                              '--backend-opt spring=torque'], stiff));
lastwarn('', '');
r = beamsim_run(stiff, 'group', 2, 'backend', 'box2d', 'backend_opt', {'spring', 'torque'});
[wmsg, wid] = lastwarn();
wmsg = regexprep(wmsg, '^beamsim_run: ', '');  % Octave's prefix
lines = strsplit(err, "\n");
check(status == 1 && strcmp(r.outcome, 'unstable') && strcmp(wid, 'beamsim:unstable') && ...
      strcmp(['beamsim: ' wmsg], lines{end}) && ~isempty(strfind(wmsg, r.instability)), ...
      'unstable trial: %s, warning %s; the program (exit %d) %s', r.outcome, wmsg, status, err);
lastwarn('', '');
s = beamsim_sweep(stiff, 'backend', 'box2d', 'backend_opt', {'spring', 'torque'});
[wmsg, wid] = lastwarn();
wmsg = regexprep(wmsg, '^beamsim_sweep: ', '');
check(strcmp(wid, 'beamsim:unstable') && ...
      sum(s.trials.outcome == find(strcmp(s.labels.outcome, 'unstable'))) == 20 && ...
      sum([s.groups.unstable]) == 20 && strncmp(wmsg, '20 of 20 trials unstable on the box2d', 37), ...
      'unstable sweep: %s', wmsg);
printf('unstable: a trial and a sweep on box2d with torque springs, said as the program says\n');

% ---- examples/fig3_1.m: the essay's Fig. 3.1 is the sweep's -------------
figdir = fullfile(tmp, 'fig');
[~, err, status] = program(exe, tmp, sprintf('sweep %s --trials 3 --quiet --out %s', h1, figdir));
check(status == 0, 'beamsim sweep: exit %d: %s', status, err);
summary = jsondecode(fileread(fullfile(figdir, 'summary.json')));
addpath(fullfile(source, 'examples'));
png = fullfile(tmp, 'fig3_1.png');
[P, F, R] = fig3_1(png, 3);
for g = 1:numel(summary.groups)
  b = summary.groups(g);
  i = find(F == b.params.effects_propulsion_force);
  j = find(R == b.params.effects_random_force_magnitude);
  check(json_same(P(j, i), b.p_traverse), 'fig3_1: F %g R %g: %g, summary.json %g', F(i), ...
        R(j), P(j, i), b.p_traverse);
end
info = dir(png);
check(numel(P) == numel(summary.groups) && numel(info) == 1 && info.bytes > 1000, ...
      'fig3_1: %d cells, the figure %s', numel(P), png);
printf('examples/fig3_1.m: %d cells as summary.json, the figure drawn\n', numel(P));

% ---- errors: the program's messages -------------------------------------
cases = {
  'run --set body.mass=-1', sprintf('run %s --set body.mass=-1', gate), ...
      @() beamsim_run(gate, 'set', {'body.mass', -1}), 'beamsim_run';
  'run --set integration.dt=0.5', sprintf('run %s --set integration.dt=0.5', gate), ...
      @() beamsim_run(gate, 'set', {'integration.dt', 0.5}), 'beamsim_run';
  'sweep --grid unknown key', sprintf('sweep %s --grid body.colour=1,2 --out %s', h1, ...
      fullfile(tmp, 'never')), @() beamsim_sweep(h1, 'grid', {'body.colour', [1 2]}), ...
      'beamsim_sweep';
  'landscape of a missing file', sprintf('landscape %s --out %s', fullfile(tmp, 'none.yaml'), ...
      fullfile(tmp, 'never')), @() beamsim_landscape(fullfile(tmp, 'none.yaml')), ...
      'beamsim_landscape';
};
for c = 1:size(cases, 1)
  [~, err, status] = program(exe, tmp, cases{c, 2});
  [id, msg] = raised(cases{c, 3});
  check(status == 2, '%s: the program exits %d', cases{c, 1}, status);
  check(strcmp(id, 'beamsim:input'), '%s: identifier %s', cases{c, 1}, id);
  check_message(cases{c, 1}, msg, err, cases{c, 4});
end
% Into a finished result: the program's refusal, naming the function's own
% argument where the program names its option.
[~, err, status] = program(exe, tmp, sprintf('landscape %s --resolution 2 --out %s', gate, landdir));
[id, msg] = raised(@beamsim_landscape, gate, 'resolution', 2, 'out', landdir);
want = strrep(regexprep(err, '^beamsim: ', ''), '--overwrite', '''overwrite'', true');
check(status == 2 && strcmp(id, 'beamsim:input') && isempty(strfind(msg, '--overwrite')) && ...
      (strcmp(msg, want) || strcmp(msg, ['beamsim_landscape: ' want])), ...
      'landscape into a finished result: %s, the program %s', msg, err);
% A group or trial out of range: the program's message counted from 1.
[~, err, status] = program(exe, tmp, sprintf('run %s --group 30', h1));
[id, msg] = raised(@beamsim_run, h1, 'group', 31);
want = regexprep(err, '^beamsim: --group 30: expected 0 to 29', ...
                 '''group'' 31: expected 1 to 30');
check(status == 2 && strcmp(id, 'beamsim:input') && ~strcmp(want, err) && ...
      (strcmp(msg, want) || strcmp(msg, ['beamsim_run: ' want])), ...
      'group 31 of 30: %s, the program %s', msg, err);
[id, msg] = raised(@beamsim_run, gate, 'trial', 0);
check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, '''trial''')), ...
      'trial 0: %s %s', id, msg);
[id, msg] = raised(@beamsim_sweep, h1, 'trails', 3);
check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, 'unknown argument ''trails''')), ...
      'a misspelt name: %s %s', id, msg);
check(~exist(fullfile(tmp, 'never'), 'dir'), 'a failed command wrote its directory');
printf('errors: %d of the program''s messages, and the arguments'' own\n', size(cases, 1));

% Regression: text holding a NUL was cut there (a 'set' value '2\0x' ran
% as 2); every text argument is refused naming it, the NUL written \x00.
nul = ['2' char(0) 'x'];
cases = {
  @() beamsim_run(gate, 'set', {'body.mass', nul}), '''body.mass'': the value "2\x00x": ';
  @() beamsim_run(gate, 'set', {['body.mass' char(0) 'zz'], 2}), ...
      '''set'': the key "body.mass\x00zz": ';
  @() beamsim_run([gate char(0) 'x']), ['''path'' "' gate '\x00x": '];
  @() beamsim_run(gate, 'backend', ['thesis' char(0)]), '''backend'' "thesis\x00": ';
  @() beamsim_run(gate, ['set' char(0) 'x'], {'body.mass', 2}), 'argument 2 "set\x00x": ';
  @() beamsim_run(gate, 'backend_opt', {'integrator', ['euler' char(0)]}), ...
      '''integrator'': the value "euler\x00": ';
  @() beamsim_sweep(h1, 'trials', 1, 'grid', {'body.mass', {nul, '3'}}), ...
      '''body.mass'': the value "2\x00x": ';
  @() beamsim_landscape([gate char(0)]), ['''scene'' "' gate '\x00": '];
};
for c = 1:size(cases, 1)
  [id, msg] = raised(cases{c, 1});
  check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, cases{c, 2})) && ...
        ~isempty(strfind(msg, 'expected text without NUL bytes')), 'NUL case %d: %s %s', c, ...
        id, msg);
end
printf('NUL in text: %d arguments refused, naming themselves\n', size(cases, 1));

% ---- a world stepped by hand -------------------------------------------
% Stepped under the trial's own forces, a step at a time, it passes through
% beamsim_run's recorded rows to the bit; after a reset, all the steps in
% one call end where the trial ends; a held force on a free body gives the
% impulse's velocity; a closed world's handle is refused.
for b = {'thesis', 'box2d', 'chipmunk'}
  r = beamsim_run(h1, 'group', 21, 'trial', 4, 'backend', b{1}, 'trajectory', true);
  w = beamsim_world('open', h1, 'group', 21, 'trial', 4, 'backend', b{1});
  n = numel(r.trajectory.t) - 1;
  for k = 1:n
    beamsim_world('step', w);
    s = beamsim_world('state', w);
    check(isequal(s.x, [r.trajectory.x(k + 1), r.trajectory.y(k + 1)]) && ...
          isequal(s.v, [r.trajectory.vx(k + 1), r.trajectory.vy(k + 1)]) && ...
          s.theta(1) == r.trajectory.theta1(k + 1) && ...
          s.contact(2) == r.trajectory.contact2(k + 1) && s.step == k, ...
          'world (%s): step %d is not the trial''s', b{1}, k);
  end
  beamsim_world('reset', w);
  beamsim_world('step', w, 'n', n);
  s = beamsim_world('state', w);
  check(isequal(s.x, [r.x_end, r.y_end]) && strcmp(s.backend, b{1}), ...
        'world (%s): the steps in one call end at [%.17g %.17g], the trial at [%.17g %.17g]', ...
        b{1}, s.x(1), s.x(2), r.x_end, r.y_end);
  beamsim_world('close', w);
end
w = beamsim_world('open', gate, 'set', {'body.start', '[500, 0]', 'effects.propulsion.force', 0});
beamsim_world('step', w, 'force', [-3 7], 'n', 250);
s = beamsim_world('state', w);
check(max(abs(s.v - [-3 7] * 250 * 0.004)) < 1e-12 && isequal(s.force, [-3 7 0]), ...
      'world: a held force gives v [%.17g %.17g]', s.v(1), s.v(2));
beamsim_world('close', w);
[id, msg] = raised(@() beamsim_world('state', w));
check(strcmp(id, 'beamsim:input') && ~isempty(strfind(msg, 'names no open world')), ...
      'a closed world: %s %s', id, msg);
printf('world: %d steps of an H1 trial on 3 backends, each the trial''s\n', n);

% Each MEX function's help (its .m file of comments beside it) says how it
% is called, and a call still runs the MEX function.
fns = {'beamsim_run', 'R = BEAMSIM_RUN(ARG, NAME, VALUE, ...)';
       'beamsim_sweep', 'S = BEAMSIM_SWEEP(EXPERIMENT, NAME, VALUE, ...)';
       'beamsim_landscape', 'L = BEAMSIM_LANDSCAPE(SCENE, NAME, VALUE, ...)';
       'beamsim_read_csv', 'T = BEAMSIM_READ_CSV(FILE)';
       'beamsim_world', 'W = BEAMSIM_WORLD(''open'', ARG, NAME, VALUE, ...)';
       'beamsim_markov', 'B = BEAMSIM_MARKOV(''build'', EXPERIMENT, ''out'', DIR, NAME, VALUE, ...)'};
for k = 1:size(fns, 1)
  text = get_help_text(fns{k, 1});
  check(~isempty(strfind(text, fns{k, 2})), 'help %s: no usage "%s" in "%s"', fns{k, 1}, ...
        fns{k, 2}, text);
  check(~isempty(regexp(which(fns{k, 1}), '\.mex$', 'once')), '%s is not the MEX function: %s', ...
        fns{k, 1}, which(fns{k, 1}));
end
printf('help: %d MEX functions say how they are called\n', size(fns, 1));
