% The Octave API on a running HIL stack (autodrive-sim + autodrive-runtime): reads NIGEL1_STATE
% for window_s of its own stamps (sim time), then drives with signed commands (autodrive.Car,
% throttle 0.7) for drive_s of sim time at 50 Hz of sim time, paced on the newest NIGEL1_STATE
% (autodrive.latest: not on the backlog the window left), then releases the car. Set before
% running: window_s, drive_s, keyfile ('' = the default key). The last line is JSON:
% state_count, first_utime, last_utime (the window), drive_first_utime, drive_last_utime,
% commands_sent.
lc = autodrive.connect();
car_name = 'NIGEL1';
state = autodrive.subscribe(lc, autodrive.channel('STATE', car_name));
first = [];
last = [];
n = 0;
while isempty(first) || double(last - first) < window_s * 1e6
  [m, type] = autodrive.next(state, 300);  % a hang guard (a loaded machine starts slowly)
  if isempty(m)
    error('no %s within 300 s', state.channel);
  end
  if ~strcmp(type, 'vehicle_state_t')
    error('%s carried a %s', state.channel, type);
  end
  if isempty(first)
    first = m.utime;
  end
  last = m.utime;
  n = n + 1;
end
car = autodrive.Car(lc, car_name, keyfile);
drive_first = [];
next_cmd = int64(0);
while isempty(drive_first) || double(m.utime - drive_first) < drive_s * 1e6
  m = autodrive.latest(state, 30);  % the newest: commands paced on the car's sim time now
  if isempty(m)
    error('no %s within 30 s while driving', state.channel);
  end
  if isempty(drive_first)
    drive_first = m.utime;
  end
  if m.utime >= next_cmd
    car.drive(0.7, 0);
    next_cmd = m.utime + 20000;  % 50 Hz of sim time
  end
end
car.release();
printf('{"state_count": %d, "first_utime": %d, "last_utime": %d, "drive_first_utime": %d, "drive_last_utime": %d, "commands_sent": %d}\n', ...
       n, first, last, drive_first, m.utime, car.sent);
