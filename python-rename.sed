# python-rename.sed: autodrive_tools (issue 42) -> the one distribution autodrive.
# Apply with: git ls-files -z tests | xargs -0 sed -i -E -f python-rename.sed
# Module names (longest first), then the path forms, then the package name itself.
# The LCM-generated Python package is now autodrive_msg (was autodrive).
s/\bautodrive_tools\.learn[.]gym_envs\b/autodrive.gym.envs/g
s/\bautodrive_tools\.command_auth\b/autodrive.core.command_auth/g
s/\bautodrive_tools\.plot_parking\b/autodrive.hil.plot_parking/g
s/\bautodrive_tools\.eye_cameras\b/autodrive.maps.eye_cameras/g
s/\bautodrive_tools\.sweep_learn\b/autodrive.learn.sweep.episodes/g
s/\bautodrive_tools\.pio_offline\b/autodrive.devtools.pio_offline/g
s/\bautodrive_tools\.sweep_cli\b/autodrive.learn.sweep.cli/g
s/\bautodrive_tools\.sweep_ray\b/autodrive.learn.sweep.jobs/g
s/\bautodrive_tools\.channels\b/autodrive.core.channels/g
s/\bautodrive_tools\.lcmtypes\b/autodrive.core.lcmtypes/g
s/\bautodrive_tools\.lcm_wire\b/autodrive.core.lcm_wire/g
s/\bautodrive_tools\.geometry\b/autodrive.core.geometry/g
s/\bautodrive_tools\.runfiles\b/autodrive.core.runfiles/g
s/\bautodrive_tools\.mapfacts\b/autodrive.maps.facts/g
s/\bautodrive_tools\.missions\b/autodrive.hil.missions/g
s/\bautodrive_tools\.vehicle\b/autodrive.core.vehicle/g
s/\bautodrive_tools\.scoring\b/autodrive.hil.scoring/g
s/\bautodrive_tools\.codegen\b/autodrive.devtools.codegen/g
s/\bautodrive_tools\.inspect\b/autodrive.devtools.inspect/g
s/\bautodrive_tools\.report\b/autodrive.hil.report/g
s/\bautodrive_tools\.paths\b/autodrive.core.settings/g
s/\bautodrive_tools\.plots\b/autodrive.core.plots/g
s/\bautodrive_tools\.learn\b/autodrive.gym/g
s/\bautodrive_tools\.pilot\b/autodrive.learn.pilot/g
s/\bautodrive_tools\.sweep\b/autodrive.learn.sweep.parking/g
s/\bautodrive_tools\.proc\b/autodrive.core.proc/g
s/\bautodrive_tools\.keys\b/autodrive.core.keys/g
s/\bautodrive_tools\.city\b/autodrive.hil.city/g
s/\bautodrive_tools\.demo\b/autodrive.hil.demo/g
s/\bautodrive_tools\.marl\b/autodrive.learn.marl/g
s#\bautodrive_tools/learn/gym_envs(\.py|/|\b)#autodrive/gym/envs\1#g
s#\bautodrive_tools/command_auth(\.py|/|\b)#autodrive/core/command_auth\1#g
s#\bautodrive_tools/plot_parking(\.py|/|\b)#autodrive/hil/plot_parking\1#g
s#\bautodrive_tools/eye_cameras(\.py|/|\b)#autodrive/maps/eye_cameras\1#g
s#\bautodrive_tools/sweep_learn(\.py|/|\b)#autodrive/learn/sweep/episodes\1#g
s#\bautodrive_tools/pio_offline(\.py|/|\b)#autodrive/devtools/pio_offline\1#g
s#\bautodrive_tools/sweep_cli(\.py|/|\b)#autodrive/learn/sweep/cli\1#g
s#\bautodrive_tools/sweep_ray(\.py|/|\b)#autodrive/learn/sweep/jobs\1#g
s#\bautodrive_tools/channels(\.py|/|\b)#autodrive/core/channels\1#g
s#\bautodrive_tools/lcmtypes(\.py|/|\b)#autodrive/core/lcmtypes\1#g
s#\bautodrive_tools/lcm_wire(\.py|/|\b)#autodrive/core/lcm_wire\1#g
s#\bautodrive_tools/geometry(\.py|/|\b)#autodrive/core/geometry\1#g
s#\bautodrive_tools/runfiles(\.py|/|\b)#autodrive/core/runfiles\1#g
s#\bautodrive_tools/mapfacts(\.py|/|\b)#autodrive/maps/facts\1#g
s#\bautodrive_tools/missions(\.py|/|\b)#autodrive/hil/missions\1#g
s#\bautodrive_tools/vehicle(\.py|/|\b)#autodrive/core/vehicle\1#g
s#\bautodrive_tools/scoring(\.py|/|\b)#autodrive/hil/scoring\1#g
s#\bautodrive_tools/codegen(\.py|/|\b)#autodrive/devtools/codegen\1#g
s#\bautodrive_tools/inspect(\.py|/|\b)#autodrive/devtools/inspect\1#g
s#\bautodrive_tools/report(\.py|/|\b)#autodrive/hil/report\1#g
s#\bautodrive_tools/paths(\.py|/|\b)#autodrive/core/settings\1#g
s#\bautodrive_tools/plots(\.py|/|\b)#autodrive/core/plots\1#g
s#\bautodrive_tools/learn(\.py|/|\b)#autodrive/gym\1#g
s#\bautodrive_tools/pilot(\.py|/|\b)#autodrive/learn/pilot\1#g
s#\bautodrive_tools/sweep(\.py|/|\b)#autodrive/learn/sweep/parking\1#g
s#\bautodrive_tools/proc(\.py|/|\b)#autodrive/core/proc\1#g
s#\bautodrive_tools/keys(\.py|/|\b)#autodrive/core/keys\1#g
s#\bautodrive_tools/city(\.py|/|\b)#autodrive/hil/city\1#g
s#\bautodrive_tools/demo(\.py|/|\b)#autodrive/hil/demo\1#g
s#\bautodrive_tools/marl(\.py|/|\b)#autodrive/learn/marl\1#g
s/\bautodrive_tools\b/autodrive/g
s#sim/mujoco_hil/maps#maps#g
s#"sim" / "mujoco_hil" / "maps"#"maps"#g
# The LCM-generated Python bindings: package autodrive_msg (lcm_types/CMakeLists.txt).
s/\bfrom autodrive import ([a-z0-9_]+_t\b)/from autodrive_msg import \1/g
s/\bimport autodrive$/import autodrive_msg/
s#gen/python/autodrive\b#gen/python/autodrive_msg#g
