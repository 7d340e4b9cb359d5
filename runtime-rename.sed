# Issue 42, runtime layout: rewrites every moved runtime/jetson path (and the MARL core's) in
# docs, READMEs, Python, the Eye and the simulator. Usage: sed -E -i -f runtime-rename.sed FILE...
# Specific files first, then whole folders (a rewritten path never matches a later rule).
# configs: one folder
s#runtime/jetson/(autonomy|pilot)/config\b#runtime/jetson/config#g
s#"runtime" / "jetson" / "(autonomy|pilot)" / "config"#"runtime" / "jetson" / "config"#g
# the MARL core: a C library of common/
s#runtime/jetson/marl_core/marl_core\.c#common/marl_core/src/marl_core.c#g
s#runtime/jetson/marl_core\b#common/marl_core#g
s#"runtime" / "jetson" / "marl_core"#"common" / "marl_core"#g
# program entry points: apps/, one per program, named after it
s#runtime/jetson/apps/runtime_main\.cpp#runtime/jetson/apps/autodrive_runtime.cpp#g
s#runtime/jetson/teleop/teleop_main\.cpp#runtime/jetson/apps/autodrive_teleop.cpp#g
s#runtime/jetson/pilot/pilot_main\.cpp#runtime/jetson/apps/autodrive_pilot.cpp#g
s#runtime/jetson/autonomy/src/main\.cpp#runtime/jetson/apps/autodrive_autonomy.cpp#g
s#runtime/jetson/behaviour/src/city_driver_main\.cpp#runtime/jetson/apps/autodrive_city_driver.cpp#g
s#runtime/jetson/marl/src/main\.cpp#runtime/jetson/apps/autodrive_marl.cpp#g
s#runtime/jetson/tools/replay_main\.cpp#runtime/jetson/apps/autodrive_replay.cpp#g
s#runtime/jetson/tools/link_bench\.cpp#runtime/jetson/apps/runtime_link_bench.cpp#g
# the fake Nano: devtools/; the rest of tools/ (runtime-link-bench, autodrive-replay): apps/
s#runtime/jetson/tools/fake_nano\.(hpp)#runtime/jetson/devtools/include/autodrive/devtools/fake_nano.\1#g
s#runtime/jetson/tools/fake_nano\.(cpp)#runtime/jetson/devtools/src/fake_nano.\1#g
s#runtime/jetson/tools\b#runtime/jetson/apps#g
# runtime/jetson/common: the runtime's core part (config, clock, serial port)
s#runtime/jetson/common/(\w+)\.hpp#runtime/jetson/core/include/autodrive/core/\1.hpp#g
s#runtime/jetson/common/(\w+)\.cpp#runtime/jetson/core/src/\1.cpp#g
s#runtime/jetson/common\b#runtime/jetson/core#g
# include/src modules: include/<m>/ becomes include/autodrive/<m>/
s#runtime/jetson/autonomy/src/config\.hpp#runtime/jetson/modules/autonomy/include/autodrive/autonomy/config.hpp#g
s#runtime/jetson/(autonomy|behaviour|marl)/include/(autonomy|behaviour|marl)/#runtime/jetson/modules/\1/include/autodrive/\2/#g
s#runtime/jetson/(autonomy|behaviour|marl)\b#runtime/jetson/modules/\1#g
# v2v
s#runtime/jetson/v2v/include/autodrive/v2v_peers\.hpp#runtime/jetson/modules/v2v/include/autodrive/v2v/v2v_peers.hpp#g
s#<autodrive/v2v_peers\.hpp>#<autodrive/v2v/v2v_peers.hpp>#g
s#runtime/jetson/v2v/(\w+)\.hpp#runtime/jetson/modules/v2v/include/autodrive/v2v/\1.hpp#g
s#runtime/jetson/v2v/(\w+)\.cpp#runtime/jetson/modules/v2v/src/\1.cpp#g
s#runtime/jetson/v2v\b#runtime/jetson/modules/v2v#g
# flat folders: <f>/x.hpp -> <part>/include/autodrive/<part>/x.hpp, <f>/x.cpp -> <part>/src/x.cpp
s#runtime/jetson/bridge/(\w+)\.hpp#runtime/jetson/drivers/nano_bridge/include/autodrive/nano_bridge/\1.hpp#g
s#runtime/jetson/bridge/(\w+)\.cpp#runtime/jetson/drivers/nano_bridge/src/\1.cpp#g
s#runtime/jetson/bridge\b#runtime/jetson/drivers/nano_bridge#g
s#runtime/jetson/(rplidar|camera)/(\w+)\.hpp#runtime/jetson/drivers/\1/include/autodrive/\1/\2.hpp#g
s#runtime/jetson/(rplidar|camera)/(\w+)\.cpp#runtime/jetson/drivers/\1/src/\2.cpp#g
s#runtime/jetson/(rplidar|camera)\b#runtime/jetson/drivers/\1#g
s#runtime/jetson/(estimator|teleop|pilot)/(\w+)\.hpp#runtime/jetson/modules/\1/include/autodrive/\1/\2.hpp#g
s#runtime/jetson/(estimator|teleop|pilot)/(\w+)\.cpp#runtime/jetson/modules/\1/src/\2.cpp#g
s#runtime/jetson/(estimator|teleop|pilot)\b#runtime/jetson/modules/\1#g
