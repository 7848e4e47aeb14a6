% Fig. 3.1 of the essay through the MEX functions: H1's traversal
% probability over the propulsive force F_prop and the random force
% magnitude R_m, 100 trials a group with their Wilson 95% intervals, as
% `beamsim sweep configs/thesis/h1_symmetric.yaml` and `beamsim plot` draw
% it (docs/figures.md). From the top of the repository, after the build:
%
%   octave --no-gui examples/fig3_1.m [fig3_1.png]      (Octave)
%   >> run examples/fig3_1.m                            (MATLAB)
%
% It prints the table of p_traverse and writes the figure (fig3_1.png by
% default).

top = fullfile(fileparts(mfilename('fullpath')), '..');
addpath(fullfile(top, 'build', 'matlab'));
out = 'fig3_1.png';
if exist('OCTAVE_VERSION', 'builtin')
  args = argv();
  if ~isempty(args) && ~isempty(regexp(args{end}, '\.(png|svg|pdf)$', 'once'))
    out = args{end};
  end
end

s = beamsim_sweep(fullfile(top, 'configs', 'thesis', 'h1_symmetric.yaml'));

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
figure('visible', 'off');
imagesc(F, R, P, [0 1]);
set(gca, 'YDir', 'normal', 'XTick', F, 'YTick', R);
t = linspace(0, 1, 256)';
colormap((1 - t) * [0.97 0.98 1] + t * [0.03 0.19 0.42]);  % white to dark blue
c = colorbar;
ylabel(c, 'p_{traverse}');
for i = 1:numel(F)
  for j = 1:numel(R)
    colour = 'k';
    if P(j, i) > 0.6
      colour = 'w';
    end
    % two lines as two labels (Octave's gnuplot toolkit draws one line each)
    dy = 0.15 * (R(end) - R(1)) / max(numel(R) - 1, 1);
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
print('-dpng', '-r100', out);
fprintf('wrote %s\n', out);
