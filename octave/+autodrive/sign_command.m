function [mac, canonical] = sign_command(key, vehicle, cmd)
  % AUTODRIVE.SIGN_COMMAND  The truncated HMAC-SHA-256 (16 bytes, int8) of a command's canonical
  % bytes, exactly as the C++ and Python signers (<autodrive/command_auth.hpp>,
  % autodrive.core.command_auth; byte order in lcm_types/autodrive/vehicle_command_t.lcm):
  %   "ADCMD1", len+vehicle, len+source, then big-endian authority (int8), counter (int64),
  %   utime (int64), seq (int32), throttle, steering (float32), headlights, indicators (int8),
  %   engaged (uint8). key: 32 bytes (uint8 or int8). cmd: a struct with those fields.
  %   HMAC from Java's javax.crypto.Mac.
  key = uint8(key(:));
  if numel(key) ~= 32
    error('autodrive:badKey', 'autodrive.sign_command: the key has %d bytes, not 32', numel(key));
  end
  % the canonical bytes built in Octave (one Java call per command for the HMAC, not one per field)
  [~, ~, endian] = computer();
  be = @(x) big_endian(x, endian == 'L');
  canonical = typecast([uint8('ADCMD1'), str_bytes(vehicle), str_bytes(cmd.source), ...
                        be(int8(cmd.authority)), be(int64(cmd.counter)), be(int64(cmd.utime)), ...
                        be(int32(cmd.seq)), be(single(cmd.throttle)), be(single(cmd.steering)), ...
                        be(int8(cmd.headlights)), be(int8(cmd.indicators)), ...
                        uint8(logical(cmd.engaged))], 'int8');
  spec = javaObject('javax.crypto.spec.SecretKeySpec', typecast(key, 'int8'), 'HmacSHA256');
  hmac = javaMethod('getInstance', 'javax.crypto.Mac', 'HmacSHA256');
  hmac.init(spec);
  digest = hmac.doFinal(canonical);
  mac = int8(digest(1:16));
end

function b = big_endian(x, host_little_endian)
  % the bytes of a number, most significant first
  b = typecast(x, 'uint8');
  if host_little_endian
    b = fliplr(b);
  end
end

function b = str_bytes(s)
  % length byte, then at most 255 bytes of s
  s = uint8(s(1:min(end, 255)));
  b = [uint8(numel(s)), s];
end
