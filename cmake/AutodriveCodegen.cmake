# Build-time generation from the project's one-place descriptions (python -m
# autodrive.devtools.codegen, with the project's venv), like lcm-gen for the message types. Each
# target is an INTERFACE library whose include dir holds one generated header.

# autodrive_codegen_header(<target> <what> <header> <source> <source option> <reader.py>):
# `python -m autodrive.devtools.codegen <what> <header> <source option> <source>` at build time.
function(autodrive_codegen_header target what header source source_option reader)
  set(python "${AUTODRIVE_ROOT}/.venv/bin/python")
  if(NOT EXISTS "${python}")
    message(FATAL_ERROR "${python} is missing: run tools/setup (it creates the project's venv)")
  endif()
  set(out_dir "${CMAKE_BINARY_DIR}/gen/${target}")
  file(GLOB generator "${AUTODRIVE_ROOT}/python/autodrive/devtools/codegen/*.py")
  add_custom_command(
    OUTPUT "${out_dir}/${header}"
    COMMAND ${CMAKE_COMMAND} -E env "PYTHONPATH=${AUTODRIVE_ROOT}/python"
            "AUTODRIVE_ROOT=${AUTODRIVE_ROOT}"
            "${python}" -m autodrive.devtools.codegen ${what} "${out_dir}/${header}"
            ${source_option} "${source}"
    DEPENDS "${source}" ${generator} "${AUTODRIVE_ROOT}/python/autodrive/${reader}"
    COMMENT "codegen: ${header} from ${source}"
    VERBATIM)
  add_custom_target(${target}_gen DEPENDS "${out_dir}/${header}")
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_gen)
  target_include_directories(${target} INTERFACE "${out_dir}")
endfunction()

# `autodrive_vehicle`: <autodrive_vehicle.h>, the car's figures from vehicle/nigel.params.
function(autodrive_vehicle_target)
  autodrive_codegen_header(autodrive_vehicle vehicle-header autodrive_vehicle.h
    "${AUTODRIVE_ROOT}/vehicle/nigel.params" --params core/vehicle.py)
endfunction()

# `autodrive_channels`: <autodrive_channels.h>, every LCM channel name from
# lcm_types/channels.yaml.
function(autodrive_channels_target)
  autodrive_codegen_header(autodrive_channels channels-header autodrive_channels.h
    "${AUTODRIVE_ROOT}/lcm_types/channels.yaml" --table core/channels.py)
endfunction()

# `autodrive_instance_rule`: <autodrive_instance_rule.h>, the sessions' instance rule
# (AUTODRIVE_INSTANCE) from lcm_types/channels.yaml.
function(autodrive_instance_rule_target)
  autodrive_codegen_header(autodrive_instance_rule instance-header autodrive_instance_rule.h
    "${AUTODRIVE_ROOT}/lcm_types/channels.yaml" --table core/channels.py)
endfunction()
