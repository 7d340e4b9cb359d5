function log = readLog(lc, file, channels)
  % AUTODRIVE.READLOG  An LCM log (lcm-logger, tools/record) as one struct array per channel:
  %   log = autodrive.readLog(lc, 'run.lcmlog');                 % every channel
  %   log = autodrive.readLog(lc, 'run.lcmlog', {'NIGEL1_STATE'}); % only these
  % log.NIGEL1_STATE(k) is a message struct (autodrive.decode) with .log_utime, the receive
  % time [us]. Messages of types this jar does not know are skipped and counted in
  % log.skipped_messages_. A missing or unreadable file is an error naming it.
  if ~exist(file, 'file')
    error('autodrive:badLog', 'autodrive.readLog: %s: no such file', file);
  end
  try
    reader = javaObject('lcm.logging.Log', file, 'r');
  catch err
    error('autodrive:badLog', 'autodrive.readLog: %s: not an LCM log (%s)', file, err.message);
  end
  log = struct();
  log.skipped_messages_ = 0;
  cells = struct();
  while true
    try
      ev = reader.readNext();
    catch
      break;  % end of the log (java.io.EOFException)
    end
    ch = char(ev.channel);
    if nargin >= 3 && ~any(strcmp(ch, channels))
      continue;
    end
    try
      m = autodrive.decode(lc, ev.data);
    catch
      log.skipped_messages_ = log.skipped_messages_ + 1;
      continue;
    end
    m.log_utime = ev.utime;
    key = matlab.lang.makeValidName(ch);
    if ~isfield(cells, key)
      cells.(key) = {};
    end
    cells.(key){end + 1} = m;
  end
  reader.close();
  for f = fieldnames(cells)'
    log.(f{1}) = [cells.(f{1}){:}];
  end
end
