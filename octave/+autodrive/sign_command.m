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
  buf = javaMethod('allocate', 'java.nio.ByteBuffer', 6 + 2 * 256 + 36);  % big-endian
  buf.put(int8('ADCMD1'));
  put_str(buf, vehicle);
  put_str(buf, cmd.source);
  buf.put(int8(cmd.authority));
  buf.putLong(int64(cmd.counter));
  buf.putLong(int64(cmd.utime));
  buf.putInt(int32(cmd.seq));
  buf.putFloat(single(cmd.throttle));
  buf.putFloat(single(cmd.steering));
  buf.put(int8(cmd.headlights));
  buf.put(int8(cmd.indicators));
  buf.put(int8(logical(cmd.engaged)));
  n = buf.position();
  all_bytes = buf.array();
  canonical = int8(all_bytes(1:n));
  spec = javaObject('javax.crypto.spec.SecretKeySpec', typecast(key, 'int8'), 'HmacSHA256');
  hmac = javaMethod('getInstance', 'javax.crypto.Mac', 'HmacSHA256');
  hmac.init(spec);
  digest = hmac.doFinal(canonical);
  mac = int8(digest(1:16));
end

function put_str(buf, s)
  b = int8(s(1:min(end, 255)));
  buf.put(int8(typecast(uint8(numel(b)), 'int8')));
  buf.put(b);
end
