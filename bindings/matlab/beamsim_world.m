%BEAMSIM_WORLD A world of beamsim stepped by hand (a MEX function).
%   W = BEAMSIM_WORLD('open', ARG, NAME, VALUE, ...) makes the world of a
%   trial on a physics backend and returns its handle. ARG and the names
%   are beamsim_run's: a scene file, an experiment file or the output
%   directory of a sweep or a comparison; 'seed', 'group' and 'trial' (from
%   1), 'backend', 'backend_opt', 'set', 'grid'. The world starts as that
%   trial starts.
%
%   BEAMSIM_WORLD('step', W) makes one step under the scene's own forces
%   (propulsion, the trial's random force, drag, ...), each computed from
%   the state the step starts at: the trial's steps as beamsim_run makes
%   them, to the bit. Names: 'n' (steps, default 1), 'force' ([FX FY] in N:
%   held over the steps instead of the scene's forces), 'torque' (N m).
%
%   S = BEAMSIM_WORLD('state', W) is the state after the last step: step,
%   t, x, v ([1 x 2]), heading, angular_velocity, theta, omega, impulse (N s),
%   contact (0 none, 1 tangent, 2 tip) and touched (one per beam), force
%   (the last step's [FX FY TORQUE]), e_kin and e_elastic (J), energy (the
%   last step's flows), impacts and backend.
%
%   BEAMSIM_WORLD('reset', W) goes back to step 0; BEAMSIM_WORLD('close', W)
%   releases the world (clear beamsim_world releases them all).
%
%   Example:
%     w = beamsim_world('open', 'configs/thesis/h1_symmetric.yaml', 'group', 21);
%     for k = 1:500
%       beamsim_world('step', w);
%       s = beamsim_world('state', w);
%       y(k) = s.x(2);
%     end
%     beamsim_world('close', w);
%
%   See also BEAMSIM_RUN, BEAMSIM_SWEEP.
