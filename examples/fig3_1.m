function [P, F, R] = fig3_1(out, trials)
%FIG3_1 The essay's Fig. 3.1 through the MEX functions.
%   FIG3_1 draws H1's traversal probability over the propulsive force
%   F_prop and the random force magnitude R_m, each group's p_traverse with
%   its Wilson 95% interval, as `beamsim sweep configs/thesis/h1_symmetric.yaml`
%   and `beamsim plot` draw it (docs/figures.md), prints the table and
%   writes the figure to fig3_1.png.
%   FIG3_1(OUT) writes it to OUT (.png, .svg or .pdf); FIG3_1(OUT, TRIALS)
%   runs TRIALS trials a group instead of the experiment's 100.
%   [P, F, R] = FIG3_1(...) returns p_traverse, a row per R_m value and a
%   column per F_prop value, and the two axes' values.
%
%   From the top of the repository, after the build:
%     octave --no-gui --eval "addpath('examples'); fig3_1('fig3_1.png')"
%     >> addpath examples; fig3_1                                (MATLAB)

  if nargin < 1
    out = 'fig3_1.png';
  end
  top = fullfile(fileparts(mfilename('fullpath')), '..');
  if ~exist('beamsim_sweep', 'file')
    addpath(fullfile(top, 'build', 'matlab'));
  end
  h1 = fullfile(top, 'configs', 'thesis', 'h1_symmetric.yaml');
  if nargin < 2
    s = beamsim_sweep(h1);
  else
    s = beamsim_sweep(h1, 'trials', trials);
  end

  % The first grid axis (F_prop) varies slowest: group (i - 1) nR + j has
  % F_prop's i-th value and R_m's j-th.
  params = [s.groups.params];
  F = unique([params.effects_propulsion_force]);
  R = unique([params.effects_random_force_magnitude]);
  P = reshape([s.groups.p_traverse], numel(R), numel(F));
  ci = reshape([s.groups.ci95], 2, numel(R), numel(F));

  fprintf('p_traverse, %d trials per group (seed %d, backend %s)\n', s.trials_per_group, ...
          s.seed, s.backend);
  fprintf('%10s |%s\n', 'R_m \ F', sprintf(' %6g', F));
  for j = numel(R):-1:1
    fprintf('%8g N |%s\n', R(j), sprintf(' %6.2f', P(j, :)));
  end

  if exist('OCTAVE_VERSION', 'builtin')
    % without a display Octave draws with gnuplot, which it warns about
    warning('off', 'Octave:gnuplot-graphics');
  end
  fig = figure('visible', 'off');
  imagesc(F, R, P, [0 1]);
  set(gca, 'YDir', 'normal', 'XTick', F, 'YTick', R);
  t = linspace(0, 1, 256)';
  colormap((1 - t) * [0.97 0.98 1] + t * [0.03 0.19 0.42]);  % white to dark blue
  c = colorbar;
  ylabel(c, 'p_{traverse}');
  % two lines as two labels (Octave's gnuplot toolkit draws one line each)
  dy = 0.15 * (R(end) - R(1)) / max(numel(R) - 1, 1);
  for i = 1:numel(F)
    for j = 1:numel(R)
      colour = 'k';
      if P(j, i) > 0.6
        colour = 'w';
      end
      text(F(i), R(j) + dy, sprintf('%.2f', P(j, i)), 'HorizontalAlignment', 'center', ...
           'FontSize', 7, 'Color', colour);
      text(F(i), R(j) - dy, sprintf('[%.2f, %.2f]', ci(1, j, i), ci(2, j, i)), ...
           'HorizontalAlignment', 'center', 'FontSize', 7, 'Color', colour);
    end
  end
  xlabel('propulsive force F_{prop} (N)');
  ylabel('random force magnitude R_m (N)');
  title(sprintf('p_{traverse} [95%% Wilson interval], %d trials per group, %s backend', ...
                s.trials_per_group, s.backend), 'FontSize', 9);
  [~, ~, ext] = fileparts(out);
  print(fig, ['-d' ext(2:end)], '-r100', out);
  close(fig);
  fprintf('wrote %s\n', out);
end
