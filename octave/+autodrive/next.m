function [msg, type] = next(sub, timeout_s)
  % AUTODRIVE.NEXT  The next message of a subscription as a struct with the .lcm file's field
  % names and units (lcm_types/autodrive/<type>.lcm), or [] when none came within timeout_s
  % (default 1 s). type: its LCM type name (e.g. 'vehicle_state_t').
  if nargin < 2
    timeout_s = 1;
  end
  msg = [];
  type = '';
  m = sub.agg.getNextMessage(round(timeout_s * 1000));
  if isempty(m)
    return;
  end
  [msg, type] = autodrive.decode(sub.lc, m.data);
end
