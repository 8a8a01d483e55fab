function octave_plant_check(plant_dir, name, out_file, k_file)
% Peer check of codyna's MAT export, run by tests/core/mat_export_test.cpp.
% Runs the exported NAME.m as a user would (from another folder, so it must
% find NAME.mat next to itself), checks what Octave can check on its own,
% then saves what it sees (save -v7, as a user brings a controller back) for
% the C++ test to compare with codyna's own numbers:
%   out_file: A_size, sys_size, eig_re, eig_im, S (Riccati solution), Ad, Bd, Cd, Dd,
%             sys_state_names, sys_input_names, sys_output_names
%   k_file:   K = lqr(sys, eye(nx), eye(nu))
  addpath(plant_dir);
  eval(name);  % the exported script; defines A, B, C, D, ..., sys in this workspace
  assert(isa(sys, 'ss'), 'the script did not build sys');
  nx = numel(state_names);
  assert(isequal(size(A), [nx nx]), 'size(A) does not match state_names');
  assert(isequal(sys.StateName(:), state_names(:)), 'sys.StateName differs from state_names');
  assert(isequal(sys.InputName(:), input_names(:)), 'sys.InputName differs from input_names');
  assert(isequal(sys.OutputName(:), output_names(:)), 'sys.OutputName differs from output_names');
  assert(isequal(plant_inputs(:), input_names(:)) && isequal(plant_outputs(:), output_names(:)), ...
         'plant_inputs/plant_outputs differ from the names in the .mat');

  A_size = size(A);
  sys_size = size(sys);
  lambda = eig(A);
  eig_re = real(lambda);
  eig_im = imag(lambda);
  [K, S] = lqr(sys, eye(nx), eye(size(B, 2)));
  [Ad, Bd, Cd, Dd] = ssdata(c2d(sys, 0.01, 'zoh'));
  sys_state_names = sys.StateName;
  sys_input_names = sys.InputName;
  sys_output_names = sys.OutputName;
  save('-v7', out_file, 'A_size', 'sys_size', 'eig_re', 'eig_im', 'S', 'Ad', 'Bd', 'Cd', 'Dd', ...
       'sys_state_names', 'sys_input_names', 'sys_output_names');
  save('-v7', k_file, 'K');
  printf('CODYNA_OK %s\n', name);
end
