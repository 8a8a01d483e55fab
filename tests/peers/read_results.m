function read_results(h5_file, expected_file)
% Peer check of codyna's HDF5 results files (io/results_file.hpp), run by
% tests/core/results_file_test.cpp:
%   octave-cli --eval "addpath('tests/peers'); read_results('run.h5', 'expected.json')"
% GNU Octave 7.3 has no h5read/h5info; load() of a plain HDF5 file is what it
% offers. It gives each dataset as a variable (groups become structs), the
% matrices transposed (one column per sample), each fixed-length string list as
% a blank-padded char matrix (one row per entry), and no attributes. This script
% checks exactly that against EXPECTED.json (the format of read_results.py; the
% "attributes" part is not visible to Octave and is skipped) and prints
% "CODYNA_RESULTS_OCTAVE_OK <datasets> <lists>"; a mismatch is an error.
  s = load(h5_file);
  e = jsondecode(fileread(expected_file));

  datasets = as_list(e.datasets);
  for k = 1:numel(datasets)
    d = datasets{k};
    got = lookup(s, d.path);
    want = d.data(:);
    shape = d.shape(:)';
    if numel(shape) == 2
      % HDF5 (N x n) row-major is Octave's n x N: same element order
      assert(isequal(size(got), fliplr(shape)), '%s: size %s, expected %s', d.path, mat2str(size(got)), ...
             mat2str(fliplr(shape)));
    end
    assert(isa(got, 'double') && numel(got) == numel(want), '%s: %s with %d elements, expected %d doubles', ...
           d.path, class(got), numel(got), numel(want));
    err = abs(got(:) - want) - 1e-15 * max(1, abs(want));
    assert(all(err <= 0), '%s: differs from the expected values by up to %g', d.path, max(abs(got(:) - want)));
  end

  lists = as_list(e.strings);
  for k = 1:numel(lists)
    l = lists{k};
    got = lookup(s, l.path);
    want = l.values;
    if isempty(want)
      want = {};
    end
    assert(ischar(got), '%s: %s, expected a char matrix', l.path, class(got));
    assert(size(got, 1) == numel(want), '%s: %d rows, expected %d names', l.path, size(got, 1), numel(want));
    if size(got, 1) > 0
      assert(isequal(cellstr(got), want(:)), '%s: {%s}, expected {%s}', l.path, strjoin(cellstr(got)', ', '), ...
             strjoin(want(:)', ', '));
    end
  end

  % the attribute groups are there, as structs without fields
  for group = {'solver', 'status', 'provenance'}
    assert(isstruct(s.(group{1})), '%s is not a group', group{1});
  end
  printf('CODYNA_RESULTS_OCTAVE_OK %d %d\n', numel(datasets), numel(lists));
end

% jsondecode gives a struct array, or a cell array when the objects differ
function c = as_list(x)
  if iscell(x)
    c = x(:);
  else
    c = num2cell(x(:));
  end
end

% s.a.b for the path 'a/b'
function v = lookup(s, path)
  parts = strsplit(path, '/');
  v = s;
  for k = 1:numel(parts)
    assert(isfield(v, parts{k}), '%s: not in the file as Octave sees it', path);
    v = v.(parts{k});
  end
end
