# python-rename.sed (issue 42): python/autodrive_tools -> the one distribution autodrive, the
# maps sim/mujoco_hil/maps -> maps, the LCM-generated Python package autodrive -> autodrive_msg.
# Apply (GNU sed, ERE): git ls-files -z tests | xargs -0 sed -i -E -f python-rename.sed
# 1. `from autodrive_tools import a, b  # c` (and from autodrive_tools.learn): one name a line,
#    since the modules now live in different subpackages.
:split
s/^([ \t]*)from (autodrive_tools|autodrive_tools\.learn) import ([^\n#(]*[^ \n#(,]), ([a-z_]+( as [a-z_]+)?)([ \t]*#[^\n]*)?$/\1from \2 import \3\6\n\1from \2 import \4\6/M
t split
# 2. each moved module imported by name from its old parent: its new parent (and name).
s/^([ \t]*)from autodrive_tools\.learn import gym_envs( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.gym import envs\2\3/M
s/^([ \t]*)from autodrive_tools\.learn import gym_envs([ \t]*#.*)?$/\1from autodrive.gym import envs as gym_envs\2/M
s/^([ \t]*)from autodrive_tools import command_auth( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import command_auth\2\3/M
s/^([ \t]*)from autodrive_tools import command_auth([ \t]*#.*)?$/\1from autodrive.core import command_auth\2/M
s/^([ \t]*)from autodrive_tools import plot_parking( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.hil import plot_parking\2\3/M
s/^([ \t]*)from autodrive_tools import plot_parking([ \t]*#.*)?$/\1from autodrive.hil import plot_parking\2/M
s/^([ \t]*)from autodrive_tools import eye_cameras( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.maps import eye_cameras\2\3/M
s/^([ \t]*)from autodrive_tools import eye_cameras([ \t]*#.*)?$/\1from autodrive.maps import eye_cameras\2/M
s/^([ \t]*)from autodrive_tools import sweep_learn( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.learn.sweep import episodes\2\3/M
s/^([ \t]*)from autodrive_tools import sweep_learn([ \t]*#.*)?$/\1from autodrive.learn.sweep import episodes as sweep_learn\2/M
s/^([ \t]*)from autodrive_tools import pio_offline( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.devtools import pio_offline\2\3/M
s/^([ \t]*)from autodrive_tools import pio_offline([ \t]*#.*)?$/\1from autodrive.devtools import pio_offline\2/M
s/^([ \t]*)from autodrive_tools import sweep_cli( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.learn.sweep import cli\2\3/M
s/^([ \t]*)from autodrive_tools import sweep_cli([ \t]*#.*)?$/\1from autodrive.learn.sweep import cli as sweep_cli\2/M
s/^([ \t]*)from autodrive_tools import sweep_ray( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.learn.sweep import jobs\2\3/M
s/^([ \t]*)from autodrive_tools import sweep_ray([ \t]*#.*)?$/\1from autodrive.learn.sweep import jobs as sweep_ray\2/M
s/^([ \t]*)from autodrive_tools import channels( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import channels\2\3/M
s/^([ \t]*)from autodrive_tools import channels([ \t]*#.*)?$/\1from autodrive.core import channels\2/M
s/^([ \t]*)from autodrive_tools import lcmtypes( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import lcmtypes\2\3/M
s/^([ \t]*)from autodrive_tools import lcmtypes([ \t]*#.*)?$/\1from autodrive.core import lcmtypes\2/M
s/^([ \t]*)from autodrive_tools import lcm_wire( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import lcm_wire\2\3/M
s/^([ \t]*)from autodrive_tools import lcm_wire([ \t]*#.*)?$/\1from autodrive.core import lcm_wire\2/M
s/^([ \t]*)from autodrive_tools import geometry( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import geometry\2\3/M
s/^([ \t]*)from autodrive_tools import geometry([ \t]*#.*)?$/\1from autodrive.core import geometry\2/M
s/^([ \t]*)from autodrive_tools import runfiles( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import runfiles\2\3/M
s/^([ \t]*)from autodrive_tools import runfiles([ \t]*#.*)?$/\1from autodrive.core import runfiles\2/M
s/^([ \t]*)from autodrive_tools import mapfacts( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.maps import facts\2\3/M
s/^([ \t]*)from autodrive_tools import mapfacts([ \t]*#.*)?$/\1from autodrive.maps import facts as mapfacts\2/M
s/^([ \t]*)from autodrive_tools import missions( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.hil import missions\2\3/M
s/^([ \t]*)from autodrive_tools import missions([ \t]*#.*)?$/\1from autodrive.hil import missions\2/M
s/^([ \t]*)from autodrive_tools\.scm import auth( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.scm.core import security\2\3/M
s/^([ \t]*)from autodrive_tools\.scm import auth([ \t]*#.*)?$/\1from autodrive.scm.core import security as auth\2/M
s/^([ \t]*)from autodrive_tools import vehicle( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import vehicle\2\3/M
s/^([ \t]*)from autodrive_tools import vehicle([ \t]*#.*)?$/\1from autodrive.core import vehicle\2/M
s/^([ \t]*)from autodrive_tools import scoring( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.hil import scoring\2\3/M
s/^([ \t]*)from autodrive_tools import scoring([ \t]*#.*)?$/\1from autodrive.hil import scoring\2/M
s/^([ \t]*)from autodrive_tools import codegen( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.devtools import codegen\2\3/M
s/^([ \t]*)from autodrive_tools import codegen([ \t]*#.*)?$/\1from autodrive.devtools import codegen\2/M
s/^([ \t]*)from autodrive_tools import inspect( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.devtools import inspect\2\3/M
s/^([ \t]*)from autodrive_tools import inspect([ \t]*#.*)?$/\1from autodrive.devtools import inspect\2/M
s/^([ \t]*)from autodrive_tools import report( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.hil import report\2\3/M
s/^([ \t]*)from autodrive_tools import report([ \t]*#.*)?$/\1from autodrive.hil import report\2/M
s/^([ \t]*)from autodrive_tools\.scm import db( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.scm.core import db\2\3/M
s/^([ \t]*)from autodrive_tools\.scm import db([ \t]*#.*)?$/\1from autodrive.scm.core import db\2/M
s/^([ \t]*)from autodrive_tools import paths( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import settings\2\3/M
s/^([ \t]*)from autodrive_tools import paths([ \t]*#.*)?$/\1from autodrive.core import settings as paths\2/M
s/^([ \t]*)from autodrive_tools import plots( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import plots\2\3/M
s/^([ \t]*)from autodrive_tools import plots([ \t]*#.*)?$/\1from autodrive.core import plots\2/M
s/^([ \t]*)from autodrive_tools import learn( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive import gym\2\3/M
s/^([ \t]*)from autodrive_tools import learn([ \t]*#.*)?$/\1from autodrive import gym as learn\2/M
s/^([ \t]*)from autodrive_tools import pilot( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.learn import pilot\2\3/M
s/^([ \t]*)from autodrive_tools import pilot([ \t]*#.*)?$/\1from autodrive.learn import pilot\2/M
s/^([ \t]*)from autodrive_tools import sweep( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.learn.sweep import parking\2\3/M
s/^([ \t]*)from autodrive_tools import sweep([ \t]*#.*)?$/\1from autodrive.learn.sweep import parking as sweep\2/M
s/^([ \t]*)from autodrive_tools import proc( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import proc\2\3/M
s/^([ \t]*)from autodrive_tools import proc([ \t]*#.*)?$/\1from autodrive.core import proc\2/M
s/^([ \t]*)from autodrive_tools import keys( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.core import keys\2\3/M
s/^([ \t]*)from autodrive_tools import keys([ \t]*#.*)?$/\1from autodrive.core import keys\2/M
s/^([ \t]*)from autodrive_tools import city( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.hil import city\2\3/M
s/^([ \t]*)from autodrive_tools import city([ \t]*#.*)?$/\1from autodrive.hil import city\2/M
s/^([ \t]*)from autodrive_tools import demo( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.hil import demo\2\3/M
s/^([ \t]*)from autodrive_tools import demo([ \t]*#.*)?$/\1from autodrive.hil import demo\2/M
s/^([ \t]*)from autodrive_tools import marl( as [a-z_]+)([ \t]*#.*)?$/\1from autodrive.learn import marl\2\3/M
s/^([ \t]*)from autodrive_tools import marl([ \t]*#.*)?$/\1from autodrive.learn import marl\2/M
# 3. dotted module names (longest first), then path forms, then the package name itself.
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
s/\bautodrive_tools\.scm[.]auth\b/autodrive.scm.core.security/g
s/\bautodrive_tools\.vehicle\b/autodrive.core.vehicle/g
s/\bautodrive_tools\.scoring\b/autodrive.hil.scoring/g
s/\bautodrive_tools\.codegen\b/autodrive.devtools.codegen/g
s/\bautodrive_tools\.inspect\b/autodrive.devtools.inspect/g
s/\bautodrive_tools\.report\b/autodrive.hil.report/g
s/\bautodrive_tools\.scm[.]db\b/autodrive.scm.core.db/g
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
s#\bautodrive_tools/scm/auth(\.py|/|\b)#autodrive/scm/core/security\1#g
s#\bautodrive_tools/vehicle(\.py|/|\b)#autodrive/core/vehicle\1#g
s#\bautodrive_tools/scoring(\.py|/|\b)#autodrive/hil/scoring\1#g
s#\bautodrive_tools/codegen(\.py|/|\b)#autodrive/devtools/codegen\1#g
s#\bautodrive_tools/inspect(\.py|/|\b)#autodrive/devtools/inspect\1#g
s#\bautodrive_tools/report(\.py|/|\b)#autodrive/hil/report\1#g
s#\bautodrive_tools/scm/db(\.py|/|\b)#autodrive/scm/core/db\1#g
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
# 4. the maps moved to the top level.
s#sim/mujoco_hil/maps#maps#g
s#"sim" / "mujoco_hil" / "maps"#"maps"#g
# 5. the LCM-generated Python bindings: package autodrive_msg (lcm_types/CMakeLists.txt).
s/\bfrom autodrive import ([a-z0-9_]+_t\b)/from autodrive_msg import \1/g
s/^import autodrive$/import autodrive_msg/
s#gen/python/autodrive\b#gen/python/autodrive_msg#g
