# dmi_add_fmu(): a dmi model (dmi_fmu.h) as FMI 2.0 and 3.0 co-simulation FMUs.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
#
#   dmi_add_fmu(<name> SOURCES <model .c and .h files>
#               [FMI_VERSIONS 2 3] [GUID <uuid>]
#               [TARGETS <FMI 2.0 target> <FMI 3.0 target>]
#               [INSTALL_DESTINATION <dir>])
#
# Builds, in the current binary directory, <name>.fmu (FMI 2.0) and
# fmi3/<name>.fmu (FMI 3.0), each holding
#   modelDescription.xml     written from the model's variable table (its
#                            errors fail the build, naming the variable);
#   binaries/<platform>/     the Linux shared library <name>.so, and the
#                            win64 DLL when the mingw-w64 cross compiler
#                            x86_64-w64-mingw32-gcc is found;
#   sources/                 the model, the framework and libdmi's GSL-free
#                            core, every .c file listed in <SourceFiles>
#                            (FMI 2.0) or sources/buildDescription.xml (FMI
#                            3.0), compiled as they are (no definitions).
# FMI_VERSIONS: the versions to build (default: 2 3).  GUID: the GUID (FMI
# 2.0) and instantiationToken (FMI 3.0); default: a name-based UUID of
# <name>, the same at every build.  TARGETS: the names of the shared-library
# targets (default <name>_fmi2 and <name>_fmi3); the target <target>_package
# packs the .fmu (built by default).  INSTALL_DESTINATION: installs
# <dir>/<name>.fmu and <dir>/fmi3/<name>.fmu.
#
# Inputs, set by dmiConfig.cmake (find_package(dmi)) or by the dmi source
# tree: DMI_FMU_FRAMEWORK_DIR (the framework's sources, fmi2/ and fmi3/
# headers, fmu.map), DMI_FMU_CORE_SOURCES (libdmi's core with dmi.h),
# DMI_FMU_INCLUDE_DIR (dmi.h, dmi_fmu.h) and DMI_FMU_COMPILE_OPTIONS (default
# -Wall -Wextra -Wpedantic; never -Werror in a user's build).
include_guard(GLOBAL)

if(NOT DEFINED DMI_FMU_COMPILE_OPTIONS)
  set(DMI_FMU_COMPILE_OPTIONS -Wall -Wextra -Wpedantic)
endif()
find_program(DMI_MINGW_CC x86_64-w64-mingw32-gcc)

# One version's binaries and package (see dmi_add_fmu): sets <target>_fmu.
function(_dmi_fmu_version name v target guid all_sources)
  set(fw ${DMI_FMU_FRAMEWORK_DIR})
  if(v STREQUAL "2")
    set(stage ${CMAKE_CURRENT_BINARY_DIR}/${name})
    set(fmu ${CMAKE_CURRENT_BINARY_DIR}/${name}.fmu)
    set(linux ${stage}/binaries/linux64)
    set(windows ${stage}/binaries/win64)
    set(other fmi3Functions.c)
  else()
    set(stage ${CMAKE_CURRENT_BINARY_DIR}/fmi3/${name})
    set(fmu ${CMAKE_CURRENT_BINARY_DIR}/fmi3/${name}.fmu)
    set(linux ${stage}/binaries/x86_64-linux)
    set(windows ${stage}/binaries/x86_64-windows)
    set(other fmi2Functions.c)
  endif()
  set(dir ${stage}/sources)
  set(originals "")
  set(shipped "")
  set(units "")
  set(names "")
  foreach(f IN LISTS all_sources)
    get_filename_component(file ${f} NAME)
    if(file STREQUAL other)
      continue()
    endif()
    list(APPEND originals ${f})
    list(APPEND shipped ${dir}/${file})
    if(file MATCHES "[.]c$")
      list(APPEND units ${dir}/${file})
      list(APPEND names ${file})
    endif()
  endforeach()
  if(v STREQUAL "3") # FMI 3.0 lists them in sources/buildDescription.xml
    set(files "")
    foreach(file IN LISTS names)
      string(APPEND files "\n      <SourceFile name=\"${file}\"/>")
    endforeach()
    set(gen ${CMAKE_CURRENT_BINARY_DIR}/${target}_sources)
    file(CONFIGURE OUTPUT ${gen}/buildDescription.xml @ONLY CONTENT
"<?xml version=\"1.0\" encoding=\"UTF-8\"?>
<!-- Written by dmi_add_fmu. -->
<fmiBuildDescription fmiVersion=\"3.0\">
  <BuildConfiguration modelIdentifier=\"@name@\">
    <SourceFileSet language=\"C99\">@files@
    </SourceFileSet>
  </BuildConfiguration>
</fmiBuildDescription>
")
    list(APPEND originals ${gen}/buildDescription.xml)
    list(APPEND shipped ${dir}/buildDescription.xml)
  endif()
  add_custom_command( # afresh: no file left over from an earlier list
    OUTPUT ${shipped}
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${dir}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
    COMMAND ${CMAKE_COMMAND} -E copy ${originals} ${dir}
    DEPENDS ${originals}
    COMMENT "Copying the sources of the FMI ${v}.0 FMU ${name}")
  set(included ${shipped})
  list(REMOVE_ITEM included ${units})
  set_source_files_properties(${included} PROPERTIES HEADER_FILE_ONLY ON)

  # The Linux binary: exports the FMI functions only, needs libc and libm.
  add_library(${target} SHARED ${units} ${shipped})
  set_target_properties(${target} PROPERTIES OUTPUT_NAME ${name} PREFIX "" C_STANDARD 99
                        C_STANDARD_REQUIRED ON C_EXTENSIONS OFF
                        LIBRARY_OUTPUT_DIRECTORY ${linux} LINK_DEPENDS ${fw}/fmu.map)
  target_include_directories(${target} PRIVATE ${dir} ${fw}/fmi${v})
  target_compile_options(${target} PRIVATE ${DMI_FMU_COMPILE_OPTIONS})
  if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES) # no build type: optimised anyway
    target_compile_options(${target} PRIVATE -O2)
  endif()
  if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
    # Calls inside the library need not go through the PLT (only fmi2*/fmi3*
    # are exported, fmu.map): libdmi's core is inlined as in libdmi.so.
    target_compile_options(${target} PRIVATE -fno-semantic-interposition)
  endif()
  target_link_libraries(${target} PRIVATE m)
  target_link_options(${target} PRIVATE -Wl,--version-script=${fw}/fmu.map)
  if(NOT DMI_SANITIZE AND NOT DMI_SANITIZE_THREAD)
    target_link_options(${target} PRIVATE -Wl,--no-undefined)
  endif()
  set(packed ${linux})

  # Windows: linked statically (imports: system DLLs only), exporting the
  # functions FMI2_Export/FMI3_Export marks in fmi2/ or fmi3/.
  if(DMI_MINGW_CC)
    file(GLOB fmi_headers ${fw}/fmi${v}/*.h)
    add_custom_command(
      OUTPUT ${windows}/${name}.dll
      COMMAND ${CMAKE_COMMAND} -E make_directory ${windows}
      COMMAND ${DMI_MINGW_CC} -std=c99 -O2 ${DMI_FMU_COMPILE_OPTIONS} -shared -static
              -static-libgcc -I${dir} -I${fw}/fmi${v} -o ${windows}/${name}.dll ${units}
      DEPENDS ${units} ${shipped} ${fmi_headers}
      COMMENT "Cross-compiling the FMI ${v}.0 FMU's ${name}.dll (mingw-w64)"
      VERBATIM)
    list(APPEND shipped ${windows}/${name}.dll)
  endif()

  add_custom_command(
    OUTPUT ${stage}/modelDescription.xml
    COMMAND ${name}_model_description ${v} ${name} ${guid} ${stage}/modelDescription.xml
            ${names}
    DEPENDS ${name}_model_description
    COMMENT "modelDescription.xml of the FMI ${v}.0 FMU ${name}"
    VERBATIM)
  add_custom_command(
    OUTPUT ${fmu}
    COMMAND ${CMAKE_COMMAND} -E rm -f ${fmu}
    COMMAND ${CMAKE_COMMAND} -E tar cf ${fmu} --format=zip modelDescription.xml binaries sources
    WORKING_DIRECTORY ${stage}
    DEPENDS ${target} ${shipped} ${stage}/modelDescription.xml
    COMMENT "Packing the FMI ${v}.0 FMU ${fmu}")
  add_custom_target(${target}_package ALL DEPENDS ${fmu})
  set(${target}_fmu ${fmu} PARENT_SCOPE)
endfunction()

function(dmi_add_fmu name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "GUID;INSTALL_DESTINATION"
                        "SOURCES;FMI_VERSIONS;TARGETS")
  if(NOT name MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
    message(FATAL_ERROR "dmi_add_fmu: the name \"${name}\" is not a C identifier (the FMU's "
                        "modelIdentifier)")
  endif()
  if(arg_UNPARSED_ARGUMENTS OR NOT arg_SOURCES)
    message(FATAL_ERROR "dmi_add_fmu(${name}): usage: dmi_add_fmu(<name> SOURCES <files> "
                        "[FMI_VERSIONS 2 3] [GUID <uuid>] [TARGETS <t2> <t3>] "
                        "[INSTALL_DESTINATION <dir>]) (extra: ${arg_UNPARSED_ARGUMENTS})")
  endif()
  if(NOT arg_FMI_VERSIONS)
    set(arg_FMI_VERSIONS 2 3)
  endif()
  foreach(v IN LISTS arg_FMI_VERSIONS)
    if(NOT v MATCHES "^[23]$")
      message(FATAL_ERROR "dmi_add_fmu(${name}): FMI_VERSIONS ${v}: only 2 and 3")
    endif()
  endforeach()
  if(NOT arg_TARGETS)
    set(arg_TARGETS ${name}_fmi2 ${name}_fmi3)
  endif()
  if(NOT arg_GUID)
    string(UUID arg_GUID NAMESPACE 6ba7b811-9dad-11d1-80b4-00c04fd430c8 NAME "dmi_add_fmu:${name}"
           TYPE SHA1)
    set(arg_GUID "{${arg_GUID}}")
  endif()

  # The FMU's files: the model's, the framework's, the generated identity
  # (the GUID) and libdmi's core.
  set(model "")
  foreach(f IN LISTS arg_SOURCES)
    get_filename_component(f ${f} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    list(APPEND model ${f})
  endforeach()
  set(gen ${CMAKE_CURRENT_BINARY_DIR}/${name}_identity)
  file(CONFIGURE OUTPUT ${gen}/fmu_identity.c @ONLY CONTENT
"/* The identity of the FMU ${name}: written by dmi_add_fmu. */
#include \"framework.h\"

const char dmi_fmu_guid[] = \"@arg_GUID@\";
const char dmi_fmu_model_name[] = \"${name}\";
")
  set(fw ${DMI_FMU_FRAMEWORK_DIR})
  set(framework ${fw}/framework.c ${fw}/framework.h ${fw}/instance.c ${fw}/instance.h
      ${fw}/fmi2Functions.c ${fw}/fmi3Functions.c ${DMI_FMU_INCLUDE_DIR}/dmi_fmu.h)
  set(all ${model} ${framework} ${gen}/fmu_identity.c ${DMI_FMU_CORE_SOURCES})
  # sources/ is one folder: a model file may not take a framework file's name.
  set(taken "")
  foreach(f IN LISTS framework DMI_FMU_CORE_SOURCES)
    get_filename_component(file ${f} NAME)
    list(APPEND taken ${file})
  endforeach()
  list(APPEND taken fmu_identity.c)
  foreach(f IN LISTS model)
    get_filename_component(file ${f} NAME)
    if(file IN_LIST taken)
      message(FATAL_ERROR "dmi_add_fmu(${name}): the model's file ${f} has the name of a file of "
                          "the framework or libdmi (${taken}): rename it")
    endif()
  endforeach()

  # The model descriptions' writer, run at build time: the model with the
  # framework's model layer and the core (every .c but the FMI side).
  set(tool_units ${fw}/modelDescription.c)
  set(tool_dirs ${fw} ${DMI_FMU_INCLUDE_DIR})
  foreach(f IN LISTS all)
    get_filename_component(file ${f} NAME)
    get_filename_component(d ${f} DIRECTORY)
    list(APPEND tool_dirs ${d})
    if(file MATCHES "[.]c$" AND NOT file MATCHES "^(instance|fmi[23]Functions)[.]c$")
      list(APPEND tool_units ${f})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES tool_dirs)
  add_executable(${name}_model_description ${tool_units})
  # a build tool: in the FMU's own folder of the build tree, not beside the project's programs
  set_target_properties(${name}_model_description PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON
                        C_EXTENSIONS OFF RUNTIME_OUTPUT_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/${name}.tools)
  target_include_directories(${name}_model_description PRIVATE ${tool_dirs})
  target_compile_options(${name}_model_description PRIVATE ${DMI_FMU_COMPILE_OPTIONS})
  target_link_libraries(${name}_model_description PRIVATE m)

  list(GET arg_TARGETS 0 t2)
  list(GET arg_TARGETS 1 t3)
  foreach(v IN LISTS arg_FMI_VERSIONS)
    _dmi_fmu_version(${name} ${v} ${t${v}} ${arg_GUID} "${all}")
    if(arg_INSTALL_DESTINATION)
      if(v STREQUAL "2")
        install(FILES ${${t2}_fmu} DESTINATION ${arg_INSTALL_DESTINATION})
      else()
        install(FILES ${${t3}_fmu} DESTINATION ${arg_INSTALL_DESTINATION}/fmi3)
      endif()
    endif()
  endforeach()
endfunction()
