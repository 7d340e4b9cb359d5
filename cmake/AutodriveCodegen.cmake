# Build-time generation from the project's one-place descriptions (python -m
# autodrive_tools.codegen, with the project's venv), like lcm-gen for the message types.
#
# autodrive_vehicle_target(<repo_root>): INTERFACE library `autodrive_vehicle` whose include dir
# holds autodrive_vehicle.h, generated from <repo_root>/vehicle/nigel.params: the car's figures
# for C and C++ code, so that no figure is typed twice.
function(autodrive_vehicle_target repo_root)
  set(python "${repo_root}/.venv/bin/python")
  if(NOT EXISTS "${python}")
    message(FATAL_ERROR "${python} is missing: run tools/setup (it creates the project's venv)")
  endif()
  set(out_dir "${CMAKE_BINARY_DIR}/gen/vehicle")
  set(header "${out_dir}/autodrive_vehicle.h")
  file(GLOB generator "${repo_root}/python/autodrive_tools/codegen/*.py")
  add_custom_command(
    OUTPUT "${header}"
    COMMAND ${CMAKE_COMMAND} -E env "PYTHONPATH=${repo_root}/python"
            "${python}" -m autodrive_tools.codegen vehicle-header "${header}"
            --params "${repo_root}/vehicle/nigel.params"
    DEPENDS "${repo_root}/vehicle/nigel.params" ${generator}
            "${repo_root}/python/autodrive_tools/vehicle.py"
    COMMENT "codegen: ${header} from vehicle/nigel.params"
    VERBATIM)
  add_custom_target(autodrive_vehicle_gen DEPENDS "${header}")
  add_library(autodrive_vehicle INTERFACE)
  add_dependencies(autodrive_vehicle autodrive_vehicle_gen)
  target_include_directories(autodrive_vehicle INTERFACE "${out_dir}")
endfunction()


# autodrive_channels_target(<repo_root>): INTERFACE library `autodrive_channels` whose include
# dir holds autodrive_channels.h, generated from <repo_root>/lcm_types/channels.yaml: every LCM
# channel name for C and C++, so that no name is typed twice.
function(autodrive_channels_target repo_root)
  set(python "${repo_root}/.venv/bin/python")
  set(out_dir "${CMAKE_BINARY_DIR}/gen/channels")
  set(header "${out_dir}/autodrive_channels.h")
  file(GLOB generator "${repo_root}/python/autodrive_tools/codegen/*.py")
  add_custom_command(
    OUTPUT "${header}"
    COMMAND ${CMAKE_COMMAND} -E env "PYTHONPATH=${repo_root}/python"
            "${python}" -m autodrive_tools.codegen channels-header "${header}"
            --table "${repo_root}/lcm_types/channels.yaml"
    DEPENDS "${repo_root}/lcm_types/channels.yaml" ${generator}
            "${repo_root}/python/autodrive_tools/channels.py"
    COMMENT "codegen: ${header} from lcm_types/channels.yaml"
    VERBATIM)
  add_custom_target(autodrive_channels_gen DEPENDS "${header}")
  add_library(autodrive_channels INTERFACE)
  add_dependencies(autodrive_channels autodrive_channels_gen)
  target_include_directories(autodrive_channels INTERFACE "${out_dir}")
endfunction()
