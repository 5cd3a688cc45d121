# The project's parts and what each may depend on, for its #includes and its links alike.
# Production (the robot's libraries): models <- calibration, matching <- tracking <- app, with
# heading and views (matching/) beside matching and global (matching/) above the three; tracking
# sits above all of matching/ (the global mode of a lost robot).
# Beside them, parts only app/ and tests/ use: render, synth (models/), evaluation (matching/),
# sim, fake_gige (tracking/); app/bench/ and tests/support/ sit at the top with app/ and tests/.
# Part P is the folder below and the library linetrack_P. Used at configure time
# (linetrack_check_link_layers) and by the ctest layers.IncludesPointDown (CheckLayers.cmake).

# Folder prefix = part, the most specific folder first.
set(LINETRACK_PART_FOLDERS
    "models/render/=render" "models/synth/=synth" "models/import/=import" "models/=models"
    "calibration/=calibration"
    "matching/evaluation/=evaluation" "matching/heading/=heading" "matching/views/=views"
    "matching/global/=global" "matching/=matching"
    "tracking/sim/=sim" "tracking/fake_gige/=fake_gige" "tracking/=tracking"
    "app/=app" "tests/=tests")

# What each checked part may include and link (itself included).
set(LINETRACK_DEPS_models models)
set(LINETRACK_DEPS_calibration calibration models)
set(LINETRACK_DEPS_matching matching models)
set(LINETRACK_DEPS_heading heading models)
set(LINETRACK_DEPS_views views models)
set(LINETRACK_DEPS_global global matching heading views models)
set(LINETRACK_DEPS_tracking tracking matching heading views global models)
set(LINETRACK_DEPS_import import models)
set(LINETRACK_DEPS_render render models)
set(LINETRACK_DEPS_synth synth models)
set(LINETRACK_DEPS_evaluation evaluation matching render synth models)
set(LINETRACK_DEPS_sim sim tracking matching render models)
set(LINETRACK_DEPS_fake_gige fake_gige)
set(LINETRACK_CHECKED_PARTS
    models import calibration matching heading views global tracking render synth evaluation sim
    fake_gige)

# Sets `out` to the part of the project path `path` (e.g. "matching/lines/x.h" -> matching), or
# to "" when the path is in none.
function(linetrack_part_of path out)
  foreach(entry IN LISTS LINETRACK_PART_FOLDERS)
    string(REPLACE "=" ";" pair "${entry}")
    list(GET pair 0 folder)
    list(GET pair 1 part)
    string(FIND "${path}" "${folder}" at)
    if(at EQUAL 0)
      set(${out} ${part} PARENT_SCOPE)
      return()
    endif()
  endforeach()
  set(${out} "" PARENT_SCOPE)
endfunction()

# Fails the configuration when a checked part's library links a linetrack_* library its part
# may not depend on.
function(linetrack_check_link_layers)
  foreach(part IN LISTS LINETRACK_CHECKED_PARTS)
    if(NOT TARGET linetrack_${part})
      continue()
    endif()
    get_target_property(links linetrack_${part} LINK_LIBRARIES)
    get_target_property(interface linetrack_${part} INTERFACE_LINK_LIBRARIES)
    foreach(lib IN LISTS links interface)
      if(lib MATCHES "^linetrack_(.+)$")
        set(used ${CMAKE_MATCH_1})
        if(NOT used IN_LIST LINETRACK_DEPS_${part})
          string(REPLACE ";" ", " allowed "${LINETRACK_DEPS_${part}}")
          message(FATAL_ERROR "linetrack_${part} links linetrack_${used}, allowed: ${allowed}")
        endif()
      endif()
    endforeach()
  endforeach()
endfunction()
