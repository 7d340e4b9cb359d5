function obj = to_java(lc, type, s)
  % AUTODRIVE.TO_JAVA  The Java LCM object of type (e.g. 'pose2d_t') filled from struct s: every
  % field of lcm_types/autodrive/<type>.lcm must be in s with a value of its kind; a missing or
  % mistyped field, or an unknown type, is an error naming it (autodrive.publish's check).
  cls = ['autodrive.' type];
  if ~isKey(lc.fields, cls)
    error('autodrive:unknownType', 'autodrive.publish: no LCM type %s in the types jar', type);
  end
  obj = javaObject(cls);
  names = lc.fields(cls);
  setters = lc.setters(cls);  % {Field, type name} per field, looked up by autodrive.connect
  for i = 1:numel(names)
    f = names{i};
    if ~isfield(s, f)
      error('autodrive:missingField', 'autodrive.publish: %s: field ''%s'' missing', type, f);
    end
    set_field(obj, type, f, s.(f), setters{i, 1}, setters{i, 2});
  end
end

function set_field(obj, type, f, v, field, kind)
  numeric = {'long', 'int', 'short', 'byte', 'float', 'double'};
  if any(strcmp(kind, numeric)) && ~(isnumeric(v) && isscalar(v) && isreal(v))
    error('autodrive:badField', 'autodrive.publish: %s: field ''%s'' must be one real number (%s)', type, f, kind);
  end
  switch kind
    case 'long',    field.setLong(obj, int64(v));
    case 'int',     field.setInt(obj, int32(v));
    case 'short',   field.setShort(obj, int16(v));
    case 'byte',    field.setByte(obj, int8(v));
    case 'float',   field.setFloat(obj, single(v));
    case 'double',  field.setDouble(obj, double(v));
    case 'boolean'
      if ~(islogical(v) || isnumeric(v)) || ~isscalar(v)
        error('autodrive:badField', 'autodrive.publish: %s: field ''%s'' must be true or false', type, f);
      end
      field.setBoolean(obj, logical(v));
    case 'java.lang.String'
      if ~ischar(v)
        error('autodrive:badField', 'autodrive.publish: %s: field ''%s'' must be text', type, f);
      end
      field.set(obj, v);
    otherwise  % arrays: [D [F [B [I [J
      if ~isnumeric(v)
        error('autodrive:badField', 'autodrive.publish: %s: field ''%s'' must be a numeric array (%s)', type, f, kind);
      end
      conv = struct('x5BD', @double, 'x5BF', @single, 'x5BB', @int8, 'x5BI', @int32, 'x5BJ', @int64, 'x5BS', @int16);
      key = ['x5B' kind(2:end)];
      if ~isfield(conv, key)
        error('autodrive:badField', 'autodrive.publish: %s: field ''%s'' of kind %s is not supported', type, f, kind);
      end
      field.set(obj, conv.(key)(v(:)));
  end
end
