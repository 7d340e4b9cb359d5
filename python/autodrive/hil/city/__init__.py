"""The smart-city cars in HIL: runtime configs per car, the start poses from the simulator's
placement, the route loops through the lights, the advisory stand-in and the scoring of a run
(violations and stop-line overshoot from ground truth)."""
