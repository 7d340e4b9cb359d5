function [msg, type] = latest(sub, timeout_s)
  % AUTODRIVE.LATEST  The newest message of a subscription as a struct (autodrive.next's), the
  % older queued ones dropped undecoded; when none is queued it waits up to timeout_s [s]
  % (default 1) and returns [] if none came. For a control loop, which acts on the newest state:
  % a loop slower than the channel (decoding in Octave takes ms) would otherwise act on a backlog
  % that lags further behind the car with every step.
  if nargin < 2
    timeout_s = 1;
  end
  while sub.agg.numMessagesAvailable() > 1
    sub.agg.getNextMessage(0);
  end
  [msg, type] = autodrive.next(sub, timeout_s);
end
