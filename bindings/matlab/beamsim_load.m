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

% A table by beamsim_read_csv (the MEX function beside this file), the
% group and trial columns counted from 1.
function t = read_csv(file)
  t = beamsim_read_csv(file);
  names = {'group', 'trial'};
  for i = 1:numel(names)
    if isfield(t, names{i}) && isnumeric(t.(names{i}))
      t.(names{i}) = t.(names{i}) + 1;
    end
  end
end
