function sub = subscribe(lc, channel)
  % AUTODRIVE.SUBSCRIBE  Queues every message of an LCM channel (a MessageAggregator) for
  % autodrive.next: sub = autodrive.subscribe(lc, autodrive.channel('STATE', 'NIGEL1')).
  sub.agg = javaObject('lcm.lcm.MessageAggregator');
  lc.java.subscribe(channel, sub.agg);
  sub.channel = channel;
  sub.lc = lc;
end
