"""What the ROS and MATLAB/Octave APIs share for their tests and `tools/bench apis`: a HIL stack
(autodrive-sim + the unchanged autodrive-runtime on real LCM, autodrive.apis.stack), a ROS
master (autodrive.apis.ros_master) and Octave with the LCM jars (autodrive.apis.octave)."""
