# Issue 42, runtime layout: the C++ side for code written against the old runtime (e.g. a branch
# that edits the city driver or the autonomy): include paths and namespaces under autodrive::.
# Usage: sed -E -i -f runtime-namespaces.sed FILE.cpp FILE.hpp ...
# includes (quoted paths rooted at runtime/jetson or a module's include/)
s#"common/(clock|config|serial_port)\.hpp"#<autodrive/core/\1.hpp>#g
s#"bridge/(\w+\.hpp)"#<autodrive/nano_bridge/\1>#g
s#["<](rplidar|camera|estimator|teleop|pilot|autonomy|behaviour|marl|v2v)/(\w+\.hpp)[">]#<autodrive/\1/\2>#g
s#<autodrive/v2v_peers\.hpp>#<autodrive/v2v/v2v_peers.hpp>#g
s#"fake_nano\.hpp"#<autodrive/devtools/fake_nano.hpp>#g
# namespaces: declarations, closing comments and using-directives
s#^namespace (est) \{#namespace autodrive::estimator {#
s#^namespace (ser) \{#namespace autodrive::serial {#
s#^namespace (clk) \{#namespace autodrive::clock {#
s#^namespace (cfg) \{#namespace autodrive::config {#
s#^namespace (cam) \{#namespace autodrive::camera {#
s#^namespace rtest \{#namespace autodrive::devtools {#
s#^namespace (bridge|rplidar|teleop|v2v|pilot|marl|behaviour|autonomy) \{#namespace autodrive::\1 {#
s#(\}\s*// namespace )est\b#\1autodrive::estimator#
s#(\}\s*// namespace )ser\b#\1autodrive::serial#
s#(\}\s*// namespace )clk\b#\1autodrive::clock#
s#(\}\s*// namespace )cfg\b#\1autodrive::config#
s#(\}\s*// namespace )cam\b#\1autodrive::camera#
s#(\}\s*// namespace )rtest\b#\1autodrive::devtools#
s#(\}\s*// namespace )(bridge|rplidar|teleop|v2v|pilot|marl|behaviour|autonomy)\b#\1autodrive::\2#
s#using namespace (autonomy|behaviour|marl|pilot);#using namespace autodrive::\1;#g
# qualified names (not already under autodrive::)
s#(^|[^:[:alnum:]_])est::#\1autodrive::estimator::#g
s#(^|[^:[:alnum:]_])ser::#\1autodrive::serial::#g
s#(^|[^:[:alnum:]_])clk::#\1autodrive::clock::#g
s#(^|[^:[:alnum:]_])cfg::#\1autodrive::config::#g
s#(^|[^:[:alnum:]_])cam::#\1autodrive::camera::#g
s#(^|[^:[:alnum:]_])rtest::(FakeNano|PtyPeer)#\1autodrive::devtools::\2#g
s#(^|[^:[:alnum:]_])(bridge|rplidar|teleop|v2v|pilot|marl|behaviour|autonomy)::#\1autodrive::\2::#g
