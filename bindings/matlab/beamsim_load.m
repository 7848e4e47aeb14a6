function d = beamsim_load(where)
%BEAMSIM_LOAD Read an output directory of beamsim into a struct.
%   D = BEAMSIM_LOAD(DIR) reads every table and JSON file of DIR, the
%   output directory of any beamsim command (run --out, sweep, compare,
%   landscape, markov, ...), and of its folders (a comparison's sides):
%     NAME.csv   D.NAME, a struct of column vectors, one per column, named
%                by the header (dots and other characters MATLAB does not
%                take in a name become underscores); a column of numbers
%                is a double column (an empty field is NaN), any other a
%                cell column of text;
%     NAME.json  D.NAME, as jsondecode reads it (summary.json, run.json,
%                manifest.json, landscape.json, ...);
%     FOLDER/    D.FOLDER, read the same way.
%   Groups and trials count from 1, as in beamsim_run and beamsim_sweep:
%   the columns named group and trial, and run.json's group and trial, are
%   the file's numbers plus 1. The .mat twins hold the same tables with the
%   file's numbers (load them with load()); figures, scripts and inputs/
%   are left out.
%
%   Example:
%     d = beamsim_load('out/h2');
%     k = find(strcmp(d.trials.outcome, 'traversed'), 1);
%     r = beamsim_run('out/h2', 'group', d.trials.group(k), 'trial', d.trials.trial(k));

  if ~ischar(where) || ~exist(where, 'dir')
    error('beamsim:input', 'beamsim_load: %s: expected an output directory of beamsim', ...
          char(where));
  end
  d = read_folder(where);
end

function d = read_folder(where)
  d = struct();
  entries = dir(where);
  for i = 1:numel(entries)
    name = entries(i).name;
    file = fullfile(where, name);
    if name(1) == '.' || strcmp(name, 'inputs')
      continue;
    end
    if entries(i).isdir
      sub = read_folder(file);
      if ~isempty(fieldnames(sub))
        d.(field_name(name)) = sub;
      end
      continue;
    end
    [~, base, ext] = fileparts(name);
    switch lower(ext)
      case '.csv'
        d.(field_name(base)) = read_csv(file);
      case '.json'
        value = jsondecode(fileread(file));
        if strcmp(name, 'run.json') && isstruct(value)
          value = from_one(value);
        end
        d.(field_name(base)) = value;
    end
  end
end

% The group and trial fields of s counted from 1.
function s = from_one(s)
  names = {'group', 'trial'};
  for i = 1:numel(names)
    if isfield(s, names{i}) && isnumeric(s.(names{i}))
      s.(names{i}) = s.(names{i}) + 1;
    end
  end
end

% A name MATLAB takes, as the MEX functions make them: any character but a
% letter, a digit or an underscore becomes an underscore, and an x goes in
% front of a name that does not start with a letter.
function f = field_name(name)
  f = regexprep(name, '[^A-Za-z0-9_]', '_');
  if isempty(f) || ~isletter(f(1))
    f = ['x' f];
  end
end

function t = read_csv(file)
  text = fileread(file);
  lines = regexp(text, '\r?\n', 'split');
  if ~isempty(lines) && isempty(lines{end})
    lines(end) = [];
  end
  if isempty(lines)
    error('beamsim:input', 'beamsim_load: %s: expected a header line, got an empty file', file);
  end
  header = split_line(lines{1});
  nc = numel(header);
  body = lines(2:end);
  n = numel(body);
  if isempty(strfind(text, '"'))
    parts = regexp(body, ',', 'split');
  else
    parts = cellfun(@split_line, body, 'UniformOutput', false);
  end
  counts = cellfun('numel', parts);
  bad = find(counts ~= nc, 1);
  if ~isempty(bad)
    error('beamsim:input', 'beamsim_load: %s:%d: expected %d fields, got %d', file, ...
          bad + 1, nc, counts(bad));
  end
  if n > 0
    cells = vertcat(parts{:});
  else
    cells = cell(0, nc);
  end
  t = struct();
  for j = 1:nc
    col = cells(:, j);
    v = str2double(col);
    empty = cellfun('isempty', col);
    name = field_name(header{j});
    if all(~isnan(v) | empty | strcmpi(col, 'nan'))
      v(empty) = NaN;
      if any(strcmp(header{j}, {'group', 'trial'}))
        v = v + 1;
      end
      t.(name) = v;
    else
      t.(name) = col;
    end
  end
end

% The fields of one CSV line, quoted fields ("a, b", "" for ") unquoted.
function f = split_line(line)
  f = {};
  field = '';
  quoted = false;
  k = 1;
  while k <= numel(line)
    c = line(k);
    if quoted
      if c == '"' && k < numel(line) && line(k + 1) == '"'
        field(end + 1) = '"';
        k = k + 1;
      elseif c == '"'
        quoted = false;
      else
        field(end + 1) = c;
      end
    elseif c == '"'
      quoted = true;
    elseif c == ','
      f{end + 1} = field;
      field = '';
    else
      field(end + 1) = c;
    end
    k = k + 1;
  end
  f{end + 1} = field;
end
