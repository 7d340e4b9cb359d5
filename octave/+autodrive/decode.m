function [msg, type] = decode(lc, data)
  % AUTODRIVE.DECODE  An encoded LCM message (int8 bytes) as a struct; its type is found by the
  % fingerprint it starts with. Bytes that are no AutoDRIVE type, or do not decode, are an error.
  data = int8(data(:));
  if numel(data) < 8
    error('autodrive:badMessage', 'autodrive.decode: %d bytes are too short for an LCM message', numel(data));
  end
  fp = lower(regexprep(sprintf('%02x', typecast(data(1:8), 'uint8')), '^0+', ''));
  if ~isKey(lc.by_fingerprint, fp)
    error('autodrive:unknownType', 'autodrive.decode: fingerprint %s is no AutoDRIVE type of this jar', fp);
  end
  cls = lc.by_fingerprint(fp);
  try
    obj = javaObject(cls, data);
  catch err
    error('autodrive:badMessage', 'autodrive.decode: a %s that does not decode (%s)', cls, err.message);
  end
  type = cls(11:end);
  msg = struct();
  names = lc.fields(cls);
  for i = 1:numel(names)
    v = obj.(names{i});
    if isjava(v) && isa(v, 'java.lang.String')
      v = char(v);
    end
    msg.(names{i}) = v;
  end
end
