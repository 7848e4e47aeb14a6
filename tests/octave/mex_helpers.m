% What the Octave tests of the MEX functions share (test_mex.m,
% test_markov.m source it): their set-up, checks, the program run, its
% messages.
1;

function check(ok, varargin)
  if ~ok
    error('test_mex:failed', varargin{:});
  end
end

% a equals the number b read from the program's JSON: Octave 7's jsondecode
% (RapidJSON without its full-precision flag) reads a number to within an
% ulp or two of the double the program wrote.
function yes = json_same(a, b)
  yes = isequal(size(a(:)), size(b(:))) && all(abs(a(:) - b(:)) <= 2 * eps(abs(b(:))));
end

% The program's run: its standard output, standard error and exit status.
function [out, err, status] = program(exe, tmp, args)
  errfile = fullfile(tmp, 'stderr.txt');
  [status, out] = system(sprintf('%s %s 2>%s', exe, args, errfile));
  err = strtrim(fileread(errfile));
end

% The error a MEX call raises: identifier and message.
function [id, msg] = raised(fn, varargin)
  id = '';
  msg = '';
  try
    fn(varargin{:});
  catch e
    id = e.identifier;
    msg = e.message;
  end
end

% The program's one-line message ("beamsim: MSG") is the MEX error's,
% which Octave prefixes with the function's name.
function check_message(what, msg, program_err, fn)
  lines = strsplit(program_err, "\n");
  line = lines{end};
  check(strncmp(line, 'beamsim: ', 9), '%s: the program said %s', what, program_err);
  want = [fn ': ' line(10:end)];
  check(strcmp(msg, want) || strcmp(msg, line(10:end)), ...
        '%s: MEX error\n  %s\nprogram\n  %s', what, msg, line);
end

% The test's arguments, BUILD SOURCE BEAMSIM TMP: TMP emptied and the MEX
% functions of BUILD on the path. The program runs as it is, whatever
% library Octave was started with (a check of the MEX code under a
% preloaded sanitizer, docs/tests.md).
function [build, source, exe, tmp] = test_setup()
  unsetenv('LD_PRELOAD');
  args = argv();
  build = args{1};
  source = args{2};
  exe = args{3};
  tmp = args{4};
  if exist(tmp, 'dir')
    confirm_recursive_rmdir(false, 'local');
    rmdir(tmp, 's');
  end
  mkdir(tmp);
  addpath(fullfile(build, 'matlab'));
end
