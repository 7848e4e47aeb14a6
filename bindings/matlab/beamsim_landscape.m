%BEAMSIM_LANDSCAPE The potential energy landscape of a scene (a MEX function).
%   L = BEAMSIM_LANDSCAPE(SCENE, NAME, VALUE, ...) computes the landscape
%   of the scene file on a grid and its barriers, as `beamsim landscape`
%   does.
%
%   Names:
%     'set'          {KEY, VALUE, ...}, scene keys set as by --set
%     'region'       [X0 X1 Y0 Y1], the grid's extent, m
%     'resolution'   the grid spacing, m
%     'out'          a directory: also write the program's files and
%                    figures there
%     'overwrite'    true: replace the result 'out' holds (without it such a
%                    directory is refused, as by `beamsim landscape`)
%
%   L.x (1 x nx) and L.y (ny x 1) are the grid's coordinates; L.e_total,
%   L.e_beam and L.e_prop ny x nx matrices, J (rows y, columns x, as
%   meshgrid and surf take them); L.theta ny x nx x n_beams, rad;
%   L.barriers the start, the far side and the passes (landscape.json's).
%
%   Example:
%     l = beamsim_landscape('configs/thesis/gate.yaml');
%     surf(l.x, l.y, l.e_total)
%
%   See also BEAMSIM_RUN, BEAMSIM_LOAD.
