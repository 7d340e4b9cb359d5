classdef Car < handle
  % AUTODRIVE.CAR  Drives one car with signed, leased commands (docs/design/safety.md):
  %   car = autodrive.Car(lc, 'NIGEL1');            % key from autodrive.default_key_path
  %   car = autodrive.Car(lc, 'NIGEL1', keyfile);
  %   car.drive(0.5, -0.2);  % throttle, steering, normalised [-1, 1]; call it at 20-50 Hz:
  %                          % the runtime stops the car when commands stop (command_timeout_ms)
  %   car.stop();            % a disengaged zero command
  %   car.release();         % stop, then fall silent: the control lease lapses (500 ms)
  % Each command is signed as source 'octave' (authority machine) with the car's key
  % (autodrive.sign_command); the first engaged command is preceded by a disengaged one, the
  % edge the Nano arms on.
  properties (SetAccess = private)
    vehicle
    source = 'octave'
    sent = 0
  end
  properties (Access = private)
    lc
    key
    channel
    seq = 0
    counter = int64(0)
    armed = false
  end
  methods
    function car = Car(lc, vehicle, keyfile)
      if nargin < 3 || isempty(keyfile)
        keyfile = autodrive.default_key_path(vehicle);
      end
      car.lc = lc;
      car.vehicle = upper(vehicle);
      car.key = autodrive.load_key(keyfile);
      car.channel = autodrive.channel('COMMAND', car.vehicle);
    end
    function drive(car, throttle, steering)
      if ~(isscalar(throttle) && isscalar(steering) && abs(throttle) <= 1 && abs(steering) <= 1)
        error('autodrive:badCommand', 'autodrive.Car.drive: throttle and steering are numbers in [-1, 1]');
      end
      if ~car.armed
        car.send(0, 0, false);
        car.armed = true;
      end
      car.send(throttle, steering, true);
    end
    function stop(car)
      car.send(0, 0, false);
    end
    function release(car)
      for i = 1:5
        car.send(0, 0, false);
      end
      car.armed = false;
    end
  end
  methods (Access = private)
    function send(car, throttle, steering, engaged)
      now = javaMethod('now', 'java.time.Instant');  % wall clock [us], as the other signers
      now_us = int64(now.getEpochSecond()) * 1000000 + int64(floor(double(now.getNano()) / 1000));
      car.counter = max(car.counter + 1, now_us);  % the anti-replay counter: strictly increasing
      cmd = struct('utime', now_us, 'seq', car.seq, 'throttle', single(throttle), ...
                   'steering', single(steering), 'headlights', 0, 'indicators', 0, ...
                   'engaged', logical(engaged), 'source', car.source, 'authority', 1, ...
                   'counter', car.counter);
      cmd.mac = autodrive.sign_command(car.key, car.vehicle, cmd);
      obj = autodrive.to_java(car.lc, 'vehicle_command_t', cmd);
      car.lc.java.publish(car.channel, obj);
      car.seq = car.seq + 1;
      car.sent = car.sent + 1;
    end
  end
end
