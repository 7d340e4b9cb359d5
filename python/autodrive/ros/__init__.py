"""The ROS 1 side of the stack (Debian bookworm's ROS: rospy 1.15, the common message packages):
autodrive.ros.topics derives the ROS topic table from lcm_types/channels.yaml, and
autodrive.ros.bridge is `autodrive-ros-bridge`, the node that maps the bus to ROS topics and ROS
commands to signed <VEH>_COMMAND. The ROS package itself (package.xml, launch, rviz) is ros/."""
