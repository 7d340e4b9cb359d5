function publish(lc, channel, type, s)
  % AUTODRIVE.PUBLISH  Publishes struct s as an LCM message of type (e.g. 'pose2d_t'): every field
  % of lcm_types/autodrive/<type>.lcm must be in s, with a value of its kind; a missing or
  % mistyped field, or an unknown type, is an error naming it. Commands to a car go through
  % autodrive.Car (signed), never here.
  if strcmp(type, 'vehicle_command_t')
    error('autodrive:unsigned', 'autodrive.publish: commands are signed: use autodrive.Car');
  end
  lc.java.publish(channel, autodrive.to_java(lc, type, s));
end
