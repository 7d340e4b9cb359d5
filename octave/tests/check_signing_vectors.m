% The Octave signer against tests/foundation/command_auth_vectors.json, the vectors the C++ and
% Python signers match byte for byte; prints "signing vectors: N ok" or errors.
here = fileparts(mfilename('fullpath'));
v = jsondecode(fileread(fullfile(here, '..', '..', 'tests', 'foundation', 'command_auth_vectors.json')));
vectors = v.vectors;
if ~iscell(vectors)
  vectors = num2cell(vectors);
end
for i = 1:numel(vectors)
  t = vectors{i};
  key = uint8(hex2dec(reshape(t.key, 2, [])'))';
  [mac, canonical] = autodrive.sign_command(key, t.vehicle, t.cmd);
  got = sprintf('%02x', typecast(canonical, 'uint8'));
  if ~strcmp(got, t.canonical_hex)
    error('vector %d: canonical bytes %s, expected %s', i, got, t.canonical_hex);
  end
  got = sprintf('%02x', typecast(mac, 'uint8'));
  if ~strcmp(got, t.mac_hex)
    error('vector %d: mac %s, expected %s', i, got, t.mac_hex);
  end
end
printf('signing vectors: %d ok\n', numel(vectors));
