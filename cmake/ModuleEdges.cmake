# The modules of mbopt and the edges allowed between them, declared once and
# checked on every configure.
#
# Each module owns directories (every .h/.cc below them, except what a module
# with a longer directory owns) or single files, and names the modules whose
# headers it may include. A pure module includes no gRPC, Protobuf, SQLite,
# CLP or threading header and uses only pure modules. The check reads the
# #include lines of every .h/.cc of the tree and fails the configure step with
# one line per include that crosses an edge not declared here, and also when
# the declared graph has a cycle, a declared directory is missing, or a
# directory holding C++ files belongs to no module. Debian installs every
# third-party header in /usr/include and every target sees the whole source
# tree, so neither the link graph nor include paths could stop an include.
#
# docs/architecture.md's module table is generated from this declaration and
# the configure step fails when it differs. After changing the declaration:
#   cmake -DROOT=. -DWRITE_DOC_TABLE=ON -P cmake/ModuleEdges.cmake
# The check alone, without configuring (ROOT is the source tree; DECLARATION
# a file of mbopt_module() calls, by default the one below):
#   cmake -DROOT=. -P cmake/ModuleEdges.cmake
include_guard(GLOBAL)
cmake_policy(VERSION 3.25)

# mbopt_module(<name> [DIRS dir...] [FILES file...] [USES module...|*]
#              [PURE] [BRIDGE] [PURE_EXCEPT file...] [LIBS target...] [SUMMARY text])
# Paths are relative to the tree's root. USES * (tests, benchmarks) means
# every module that does not itself use *: such a module is a leaf, since
# anything using it would close a cycle. PURE_EXCEPT names the files of a
# pure module allowed a third-party include a pure module may not have (the
# one CLP adapter); their in-repo edges are still checked. BRIDGE: the module
# may use modules on both sides of a separation (MBOPT_SEPARATED_TREES), and
# in exchange only leaves (tests, benchmarks) may use it: the in-process run,
# a job whose evaluator is this process's engine. LIBS (the CMake
# targets built from the module) and SUMMARY only document: they are columns
# of the table in docs/architecture.md.
function(mbopt_module name)
  cmake_parse_arguments(ARG "PURE;BRIDGE" "SUMMARY" "DIRS;FILES;USES;PURE_EXCEPT;LIBS" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "mbopt_module(${name}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  get_property(modules GLOBAL PROPERTY MBOPT_MODULES)
  if(name IN_LIST modules)
    message(FATAL_ERROR "mbopt_module(${name}) is declared twice")
  endif()
  set_property(GLOBAL APPEND PROPERTY MBOPT_MODULES ${name})
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_DIRS "${ARG_DIRS}")
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_FILES "${ARG_FILES}")
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_USES "${ARG_USES}")
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_PURE ${ARG_PURE})
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_BRIDGE ${ARG_BRIDGE})
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_PURE_EXCEPT "${ARG_PURE_EXCEPT}")
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_SUMMARY "${ARG_SUMMARY}")
  set_property(GLOBAL PROPERTY MBOPT_MODULE_${name}_LIBS "${ARG_LIBS}")
endfunction()

# mbopt_module_exempt(<dir> <reason>): a directory whose C++ files belong to
# no module and are not scanned.
function(mbopt_module_exempt dir reason)
  set_property(GLOBAL APPEND PROPERTY MBOPT_MODULE_EXEMPT ${dir})
  set_property(GLOBAL PROPERTY MBOPT_MODULE_EXEMPT_${dir} "${reason}")
endfunction()

# Headers a pure module may not include (the path inside <> or "").
set(MBOPT_IMPURE_HEADER_REGEX
  "^(grpc[^/]*/|google/protobuf/|sqlite3\\.h$|coin/|coin-or/|Clp[A-Za-z_]*\\.hpp$|Coin[A-Za-z_]*\\.hpp$|(thread|mutex|shared_mutex|condition_variable|future|stop_token|semaphore|latch|barrier)$|pthread\\.h$)|\\.pb\\.h$")
# Generated protobuf code: owned by the module that declares the prefix.
set(MBOPT_GENERATED_PROTO_PREFIX "mbopt/v1/")

# The modules of mbopt. docs/architecture.md shows this table; keep the
# summaries short, they are its last column.
function(mbopt_declare_modules)
  # The base: no in-repo dependency.
  mbopt_module(common DIRS common PURE
    LIBS mbopt_common
    SUMMARY "status macros and checks (Abseil status only)")
  mbopt_module(version DIRS common/version USES common PURE
    LIBS mbopt_version
    SUMMARY "the release, the commit a program was built from, the schema versions (`--version`)")
  mbopt_module(packed_doubles DIRS common/packed_doubles USES common PURE
    LIBS mbopt_packed_doubles
    SUMMARY "vectors of doubles packed losslessly (prediction, zlib) for results on the wire and in the log")
  mbopt_module(x509 DIRS common/x509 USES common
    LIBS mbopt_x509
    SUMMARY "X.509 certificates read and shown (OpenSSL): owned pointers, PEM, host names, dates")
  mbopt_module(secure_channel DIRS common/secure_channel USES x509 common
    LIBS mbopt_secure_channel
    SUMMARY "a client's connection to the server (CLI and worker): TLS and token from options or the environment, failures in words")
  mbopt_module(proto DIRS proto
    LIBS mbopt_proto
    SUMMARY "the file and wire schemas (generated `mbopt/v1/*.pb.h` belong here)")
  mbopt_module(spec DIRS spec USES common PURE
    LIBS mbopt_spec
    SUMMARY "the study and scene as domain types, the study layout")
  mbopt_module(spec_io DIRS spec/io USES spec common proto
    LIBS mbopt_spec_io
    SUMMARY "boundary: text-format study and scene files to spec types")

  # The optimizer's numerical core.
  mbopt_module(lp DIRS server/lp USES common PURE
    PURE_EXCEPT server/lp/clp_lp_solver.cc
    LIBS mbopt_lp mbopt_lp_clp
    SUMMARY "the LP interface (CLP only in `clp_lp_solver.cc`)")
  mbopt_module(slp DIRS server/slp USES lp common PURE
    LIBS mbopt_slp
    SUMMARY "the SLP optimizer core (the LP solver is injected)")
  mbopt_module(jobs DIRS server/jobs USES slp lp spec packed_doubles common PURE
    LIBS mbopt_jobs
    SUMMARY "a job: the one driver of the SLP core, with intake, replay, record codec and the analysis record")

  # The analysis engine's numerical core, bottom up.
  mbopt_module(budget DIRS worker/budget USES spec common PURE
    LIBS mbopt_analysis_budget
    SUMMARY "the budget of one analysis: a deadline on the caller's clock, a step budget, a cancel flag")
  mbopt_module(sundials DIRS worker/sundials USES budget spec common PURE
    LIBS mbopt_cvodes
    SUMMARY "the SUNDIALS layer: owned handles, the CVODES integrator wrapper, integrator failures in words, integration across kinks")
  mbopt_module(lumped DIRS worker/lumped USES budget sundials spec common PURE
    LIBS mbopt_lumped_model mbopt_lumped mbopt_lumped_sensitivity
    SUMMARY "lumped scenes (small motion, linear): the model's M, K, C and inputs, dynamics with CVODES, forward sensitivities")
  mbopt_module(fmu DIRS worker/fmu USES budget sundials spec PURE
    LIBS mbopt_fmu mbopt_fmu_scene
    SUMMARY "FMI 2.0 and 3.0 FMUs: the archive unpacked (libzip), the model description (pugixml), the binary loaded (dlopen), Model Exchange integrated with CVODES with state and time events, Co-Simulation stepped, and the `fmu` scene's analysis")
  mbopt_module(multibody DIRS worker/multibody USES budget sundials spec common PURE
    LIBS mbopt_multibody
    SUMMARY "general planar multibody systems: equations in absolute coordinates, assembly, kinematics and inverse dynamics, static equilibrium (KINSOL), forward dynamics (IDAS, or ARKODE's explicit Runge-Kutta with projection), simulator sensitivities, the linkage scenes' front end and the floating-frame formulation of flexible links (CVODES)")
  mbopt_module(spatial DIRS worker/spatial USES multibody budget spec common PURE
    LIBS mbopt_spatial
    SUMMARY "spatial multibody systems: the model, equations in absolute coordinates with Euler parameters as a multibody ConstrainedSystem (integrated by its IDAS forward dynamics), assembly, Euler angles, the `spatial` scene's analysis and its drawing")
  mbopt_module(engine DIRS worker/engine USES budget fmu multibody spatial lumped spec common PURE
    LIBS mbopt_engine mbopt_study_values mbopt_study_sensitivities mbopt_evaluate_study mbopt_scene_drawing
    SUMMARY "one analysis of a scene (the table of model kinds), the one evaluation of a study at a design point, and the drawing of a scene")
  mbopt_module(local_run DIRS tests/testing/local_run USES jobs slp lp engine budget spec common PURE BRIDGE
    LIBS mbopt_local_run
    SUMMARY "test and benchmark support: a study optimized in this process, a job with an in-process evaluator")

  # Plumbing and boundaries.
  mbopt_module(store DIRS server/store USES jobs spec packed_doubles common
    LIBS mbopt_store
    SUMMARY "the SQLite job database")
  mbopt_module(scheduler DIRS server/scheduler USES common
    LIBS mbopt_scheduler
    SUMMARY "task queue, worker registry, leases (threads, an injected clock)")
  mbopt_module(job_manager DIRS server/jobs/manager USES jobs lp scheduler store spec common
    LIBS mbopt_job_manager
    SUMMARY "the server's jobs: jobs, scheduler and store meet (threads, an injected clock)")
  mbopt_module(auth DIRS server/auth USES x509 common
    LIBS mbopt_auth
    SUMMARY "who may call the server: tokens and their hashed table, roles, TLS certificates (OpenSSL)")
  mbopt_module(service DIRS server/service USES auth job_manager jobs lp scheduler store spec spec_io proto common
    LIBS mbopt_service mbopt_service_convert
    SUMMARY "boundary: the gRPC services and the server object")
  mbopt_module(server_main DIRS server/main USES version service auth store jobs common
    LIBS mbopt_refused_connection mbopt-server
    SUMMARY "the `mbopt-server` program")
  mbopt_module(external DIRS worker/external USES engine spec_io spec proto common
    LIBS mbopt_external mbopt_external_drivers_file
    SUMMARY "analyses run by external simulation codes: declared drivers (their file), per-analysis folders, process groups with a time limit, results files, external scenes mapped onto the engine's reports")
  mbopt_module(worker_service DIRS worker/service USES secure_channel external engine budget fmu spec spec_io proto packed_doubles common
    LIBS mbopt_worker_service
    SUMMARY "boundary: the worker's server connection and task evaluation")
  mbopt_module(worker_main DIRS worker/main USES version worker_service external engine budget spec spec_io proto common
    LIBS mbopt_worker_eval mbopt-worker
    SUMMARY "the `mbopt-worker` program")
  mbopt_module(report DIRS client/report USES spec common PURE
    LIBS mbopt_report
    SUMMARY "the job report page, from `ReportData`, and the animated drawings of scenes")
  mbopt_module(report_proto
    FILES client/report/report_from_proto.h client/report/report_from_proto.cc
    USES report proto common
    LIBS mbopt_report_proto
    SUMMARY "boundary: `GetJobResponse` to `ReportData`")
  mbopt_module(client DIRS client USES version secure_channel report report_proto spec_io spec proto common
    LIBS mbopt_client mbopt
    SUMMARY "the `mbopt` CLI")

  # Leaves (USES *): they may use every module that is not a leaf, and no
  # module may use them.
  mbopt_module(tests DIRS tests USES *
    SUMMARY "tests and their support code")
  mbopt_module(bench DIRS bench USES * tests
    SUMMARY "benchmarks and measurement programs (they share scenes with the tests)")
  mbopt_module_exempt(tests/module_edges/fixtures
    "small trees the checker's own test scans, wrong on purpose")
endfunction()

# Modules no module may depend on across these directory prefixes: the
# server and the worker meet only in the wire schema and in spec.
set(MBOPT_SEPARATED_TREES "server:worker" "worker:server" "client:server" "client:worker")

function(_mbopt_me_get var name what)
  get_property(value GLOBAL PROPERTY MBOPT_MODULE_${name}_${what})
  set(${var} "${value}" PARENT_SCOPE)
endfunction()

# The modules `name` may use, with * expanded.
function(_mbopt_me_uses var name)
  _mbopt_me_get(uses ${name} USES)
  if("*" IN_LIST uses)
    get_property(modules GLOBAL PROPERTY MBOPT_MODULES)
    list(REMOVE_ITEM uses "*")
    foreach(other IN LISTS modules)
      _mbopt_me_get(other_uses ${other} USES)
      if(NOT other STREQUAL name AND NOT "*" IN_LIST other_uses AND NOT other IN_LIST uses)
        list(APPEND uses ${other})
      endif()
    endforeach()
  endif()
  set(${var} "${uses}" PARENT_SCOPE)
endfunction()

# Errors in the declaration itself: unknown or missing names, impure uses of
# pure modules, edges across separated trees, cycles.
function(_mbopt_me_check_declaration root errors_var)
  set(errors "")
  get_property(modules GLOBAL PROPERTY MBOPT_MODULES)
  set(claimed "")
  foreach(name IN LISTS modules)
    _mbopt_me_get(dirs ${name} DIRS)
    _mbopt_me_get(files ${name} FILES)
    _mbopt_me_get(uses ${name} USES)
    _mbopt_me_get(pure ${name} PURE)
    _mbopt_me_get(pure_except ${name} PURE_EXCEPT)
    _mbopt_me_get(bridge ${name} BRIDGE)
    if(NOT dirs AND NOT files)
      string(APPEND errors "module ${name} owns no directory and no file\n")
    endif()
    foreach(dir IN LISTS dirs)
      if(NOT IS_DIRECTORY "${root}/${dir}")
        string(APPEND errors "module ${name} declares directory \"${dir}\", which does not exist\n")
      endif()
    endforeach()
    foreach(file IN LISTS files pure_except)
      if(NOT EXISTS "${root}/${file}" OR IS_DIRECTORY "${root}/${file}")
        string(APPEND errors "module ${name} declares file \"${file}\", which does not exist\n")
      endif()
    endforeach()
    foreach(path IN LISTS dirs files)
      if(path IN_LIST claimed)
        string(APPEND errors "\"${path}\" is declared by two modules (one is ${name})\n")
      endif()
      list(APPEND claimed ${path})
    endforeach()
    foreach(used IN LISTS uses)
      if(used STREQUAL "*")
        continue()
      endif()
      if(NOT used IN_LIST modules)
        string(APPEND errors "module ${name} uses ${used}, which is not a declared module\n")
        continue()
      endif()
      _mbopt_me_get(used_pure ${used} PURE)
      if(pure AND NOT used_pure)
        string(APPEND errors "pure module ${name} uses ${used}, which is not pure\n")
      endif()
      _mbopt_me_get(used_bridge ${used} BRIDGE)
      if(used_bridge AND NOT "*" IN_LIST uses)
        string(APPEND errors "module ${name} uses ${used}, a bridge between the server and the worker: only tests and benchmarks may\n")
      endif()
      if(bridge)
        continue()
      endif()
      _mbopt_me_get(used_dirs ${used} DIRS)
      _mbopt_me_get(used_files ${used} FILES)
      foreach(pair IN LISTS MBOPT_SEPARATED_TREES)
        string(REPLACE ":" ";" pair "${pair}")
        list(GET pair 0 from)
        list(GET pair 1 to)
        set(in_from FALSE)
        set(in_to FALSE)
        foreach(path IN LISTS dirs files)
          if(path MATCHES "^${from}(/|$)")
            set(in_from TRUE)
          endif()
        endforeach()
        foreach(path IN LISTS used_dirs used_files)
          if(path MATCHES "^${to}(/|$)")
            set(in_to TRUE)
          endif()
        endforeach()
        if(in_from AND in_to)
          string(APPEND errors "module ${name} (${from}/) uses ${used} (${to}/): no ${from}/ module may use a ${to}/ module\n")
        endif()
      endforeach()
    endforeach()
  endforeach()

  # Cycles: peel off modules whose uses are all peeled; what remains lies on
  # or behind a cycle. Follow uses within the remainder to name one cycle.
  set(remaining ${modules})
  set(progress TRUE)
  while(progress)
    set(progress FALSE)
    foreach(name IN LISTS remaining)
      _mbopt_me_uses(uses ${name})
      set(blocked FALSE)
      foreach(used IN LISTS uses)
        if(used IN_LIST remaining AND NOT used STREQUAL name)
          set(blocked TRUE)
          break()
        endif()
      endforeach()
      if(NOT blocked)
        list(REMOVE_ITEM remaining ${name})
        set(progress TRUE)
      endif()
    endforeach()
  endwhile()
  if(remaining)
    list(GET remaining 0 current)
    set(path "")
    while(NOT current IN_LIST path)
      list(APPEND path ${current})
      _mbopt_me_uses(uses ${current})
      foreach(used IN LISTS uses)
        if(used IN_LIST remaining)
          set(current ${used})
          break()
        endif()
      endforeach()
    endwhile()
    list(FIND path ${current} start)
    list(SUBLIST path ${start} -1 cycle)
    list(APPEND cycle ${current})
    list(JOIN cycle " -> " cycle_text)
    string(APPEND errors "the declared module graph has a cycle: ${cycle_text}\n")
  endif()
  set(${errors_var} "${errors}" PARENT_SCOPE)
endfunction()

# Sets owner_of(<path>) lookups up: exact files first, then the longest
# declared directory that contains the path.
function(_mbopt_me_index)
  get_property(modules GLOBAL PROPERTY MBOPT_MODULES)
  set(keyed "")
  foreach(name IN LISTS modules)
    _mbopt_me_get(dirs ${name} DIRS)
    _mbopt_me_get(files ${name} FILES)
    foreach(dir IN LISTS dirs)
      string(LENGTH "${dir}" length)
      math(EXPR key "10000 - ${length}")
      list(APPEND keyed "${key}|${dir}|${name}")
    endforeach()
    foreach(file IN LISTS files)
      set_property(GLOBAL PROPERTY MBOPT_ME_OWNER_FILE_${file} ${name})
    endforeach()
  endforeach()
  list(SORT keyed)
  set_property(GLOBAL PROPERTY MBOPT_ME_DIRS_LONGEST_FIRST "${keyed}")
endfunction()

function(_mbopt_me_owner var path)
  get_property(owner GLOBAL PROPERTY MBOPT_ME_OWNER_FILE_${path})
  get_property(known GLOBAL PROPERTY MBOPT_ME_OWNER_FILE_${path} SET)
  if(NOT known)
    get_property(keyed GLOBAL PROPERTY MBOPT_ME_DIRS_LONGEST_FIRST)
    foreach(entry IN LISTS keyed)
      string(REPLACE "|" ";" entry "${entry}")
      list(GET entry 1 dir)
      string(FIND "${path}" "${dir}/" at)
      if(at EQUAL 0)
        list(GET entry 2 owner)
        break()
      endif()
    endforeach()
    set_property(GLOBAL PROPERTY MBOPT_ME_OWNER_FILE_${path} "${owner}")
  endif()
  set(${var} "${owner}" PARENT_SCOPE)
endfunction()

function(_mbopt_me_line_of var file text)
  file(READ "${file}" content)
  string(FIND "${content}" "${text}" at)
  string(SUBSTRING "${content}" 0 ${at} before)
  string(REGEX MATCHALL "\n" newlines "${before}")
  list(LENGTH newlines count)
  math(EXPR line "${count} + 1")
  set(${var} ${line} PARENT_SCOPE)
endfunction()

# mbopt_check_module_edges(ROOT <dir> [DOC <file>] [FILES_VAR <var>]
#                          [ERRORS_VAR <var>])
# Checks the modules declared so far against the tree at ROOT. Reports each
# violation as an error (or, with ERRORS_VAR, returns them). DOC: a markdown
# file (relative to ROOT) whose module table must be the generated one.
# FILES_VAR: receives the C++ files scanned (absolute), for build-time
# dependencies.
function(mbopt_check_module_edges)
  cmake_parse_arguments(ARG "" "ROOT;DOC;FILES_VAR;ERRORS_VAR" "" ${ARGN})
  get_filename_component(root "${ARG_ROOT}" ABSOLUTE)
  _mbopt_me_check_declaration("${root}" errors)
  _mbopt_me_index()
  get_property(exempt GLOBAL PROPERTY MBOPT_MODULE_EXEMPT)

  # Every C++ file of the tree, except hidden and build directories.
  file(GLOB top LIST_DIRECTORIES true RELATIVE "${root}" "${root}/*")
  set(scanned "")
  set(top_dirs "")
  foreach(entry IN LISTS top)
    # A build directory has CMakeFiles/ from the start of its first configure
    # (CMakeCache.txt only at its end).
    if(entry MATCHES "^\\." OR EXISTS "${root}/${entry}/CMakeCache.txt" OR EXISTS "${root}/${entry}/CMakeFiles")
      continue()
    endif()
    if(IS_DIRECTORY "${root}/${entry}")
      list(APPEND top_dirs ${entry})
      file(GLOB_RECURSE found RELATIVE "${root}" "${root}/${entry}/*.h" "${root}/${entry}/*.cc")
      list(APPEND scanned ${found})
    elseif(entry MATCHES "\\.(h|cc)$")
      list(APPEND scanned ${entry})
    endif()
  endforeach()
  list(SORT scanned)

  set(unowned_dirs "")
  set(files_out "")
  foreach(file IN LISTS scanned)
    set(skip FALSE)
    foreach(dir IN LISTS exempt)
      string(FIND "${file}" "${dir}/" at)
      if(at EQUAL 0)
        set(skip TRUE)
      endif()
    endforeach()
    if(skip)
      continue()
    endif()
    list(APPEND files_out "${root}/${file}")
    _mbopt_me_owner(module "${file}")
    if(NOT module)
      get_filename_component(dir "${file}" DIRECTORY)
      if(NOT dir IN_LIST unowned_dirs)
        list(APPEND unowned_dirs "${dir}")
        string(APPEND errors "directory \"${dir}/\" holds C++ files (${file}) but belongs to no module; declare it in cmake/ModuleEdges.cmake\n")
      endif()
      continue()
    endif()
    _mbopt_me_get(pure ${module} PURE)
    _mbopt_me_get(pure_except ${module} PURE_EXCEPT)
    if(file IN_LIST pure_except)
      set(pure FALSE)
    endif()
    _mbopt_me_uses(uses ${module})
    file(STRINGS "${root}/${file}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"][^>\"]+[>\"]")
    foreach(line IN LISTS lines)
      string(REGEX MATCH "^[ \t]*#[ \t]*include[ \t]*([<\"])([^>\"]+)[>\"]" _ "${line}")
      set(open "${CMAKE_MATCH_1}")
      set(included "${CMAKE_MATCH_2}")
      if(open STREQUAL "<")
        set(shown "<${included}>")
      else()
        set(shown "\"${included}\"")
      endif()
      set(target "")
      string(FIND "${included}" "${MBOPT_GENERATED_PROTO_PREFIX}" at)
      if(at EQUAL 0)
        _mbopt_me_owner(target "proto/${included}")
        if(NOT target)
          set(target proto)
        endif()
      else()
        _mbopt_me_owner(target "${included}")
      endif()
      set(problem "")
      if(target)
        if(NOT target STREQUAL module AND NOT target IN_LIST uses)
          list(JOIN uses ", " allowed)
          if(NOT allowed)
            set(allowed "(no other module)")
          endif()
          set(problem "module ${module} includes ${shown} of module ${target}; ${module} may use only: ${allowed}")
        elseif(pure AND NOT target STREQUAL module)
          _mbopt_me_get(target_pure ${target} PURE)
          if(NOT target_pure)
            set(problem "pure module ${module} includes ${shown} of module ${target}, which is not pure")
          endif()
        endif()
      else()
        string(REGEX MATCH "^[^/]+" first "${included}")
        if(included MATCHES "/" AND first IN_LIST top_dirs)
          set(problem "module ${module} includes ${shown}, which no module owns")
        elseif(pure AND included MATCHES "${MBOPT_IMPURE_HEADER_REGEX}")
          set(problem "pure module ${module} includes ${shown}; a pure module includes no gRPC, Protobuf, SQLite, CLP or threading header")
        endif()
      endif()
      if(problem)
        _mbopt_me_line_of(line_number "${root}/${file}" "${line}")
        string(APPEND errors "${file}:${line_number}: ${problem}\n")
      endif()
    endforeach()
  endforeach()

  if(ARG_DOC)
    mbopt_module_table(table)
    file(READ "${root}/${ARG_DOC}" doc)
    _mbopt_me_doc_table(current "${doc}")
    if(NOT current STREQUAL table)
      string(APPEND errors "${ARG_DOC}: its module table is not the one declared in cmake/ModuleEdges.cmake; regenerate it with: cmake -DROOT=. -DWRITE_DOC_TABLE=ON -P cmake/ModuleEdges.cmake\n")
    endif()
  endif()

  if(ARG_FILES_VAR)
    set(${ARG_FILES_VAR} "${files_out}" PARENT_SCOPE)
  endif()
  if(ARG_ERRORS_VAR)
    set(${ARG_ERRORS_VAR} "${errors}" PARENT_SCOPE)
    return()
  endif()
  mbopt_report_module_edge_errors("${errors}" TRUE)
endfunction()

# One error message per violation; FATAL when `enforce`, warnings otherwise.
function(mbopt_report_module_edge_errors errors enforce)
  if(errors STREQUAL "")
    return()
  endif()
  # Lines that begin with a space are printed as they are, not re-wrapped.
  string(REGEX MATCHALL "\n" newlines "${errors}")
  list(LENGTH newlines count)
  string(REGEX REPLACE "\n$" "" text "${errors}")
  string(REPLACE "\n" "\n  " text "  ${text}")
  set(text "${text}\n  (${count} violation(s). The allowed edges are the module table of\n  docs/architecture.md, declared in cmake/ModuleEdges.cmake.)")
  if(enforce)
    message(FATAL_ERROR "Module edges:\n${text}")
  else()
    message(WARNING "Module edges (not enforced: MBOPT_ENFORCE_MODULE_EDGES is OFF):\n${text}")
  endif()
endfunction()

set(MBOPT_MODULE_TABLE_BEGIN "<!-- module table: generated from cmake/ModuleEdges.cmake; do not edit -->")
set(MBOPT_MODULE_TABLE_END "<!-- end of module table -->")

function(_mbopt_me_doc_table var doc)
  string(FIND "${doc}" "${MBOPT_MODULE_TABLE_BEGIN}" begin)
  string(FIND "${doc}" "${MBOPT_MODULE_TABLE_END}" end)
  if(begin LESS 0 OR end LESS begin)
    set(${var} "(no module table)" PARENT_SCOPE)
    return()
  endif()
  math(EXPR length "${end} - ${begin}")
  string(SUBSTRING "${doc}" ${begin} ${length} table)
  set(${var} "${table}" PARENT_SCOPE)
endfunction()

# The markdown table of the declared modules (from the begin marker up to,
# not including, the end marker).
function(mbopt_module_table var)
  get_property(modules GLOBAL PROPERTY MBOPT_MODULES)
  set(table "${MBOPT_MODULE_TABLE_BEGIN}\n")
  string(APPEND table "| module | owns | may include headers of | pure | libraries | what it is |\n")
  string(APPEND table "|---|---|---|---|---|---|\n")
  foreach(name IN LISTS modules)
    _mbopt_me_get(dirs ${name} DIRS)
    _mbopt_me_get(files ${name} FILES)
    _mbopt_me_get(uses ${name} USES)
    _mbopt_me_get(pure ${name} PURE)
    _mbopt_me_get(summary ${name} SUMMARY)
    _mbopt_me_get(libs ${name} LIBS)
    set(libs_text "")
    foreach(lib IN LISTS libs)
      list(APPEND libs_text "`${lib}`")
    endforeach()
    list(JOIN libs_text ", " libs_text)
    if(libs_text STREQUAL "")
      set(libs_text "–")
    endif()
    set(owns "")
    foreach(dir IN LISTS dirs)
      list(APPEND owns "`${dir}/`")
    endforeach()
    foreach(file IN LISTS files)
      list(APPEND owns "`${file}`")
    endforeach()
    list(JOIN owns ", " owns)
    if("*" IN_LIST uses)
      list(REMOVE_ITEM uses "*")
      set(uses_text "every module but the leaves")
      if(uses)
        list(JOIN uses ", " extra)
        string(APPEND uses_text ", and ${extra}")
      endif()
    elseif(uses)
      list(JOIN uses ", " uses_text)
    else()
      set(uses_text "–")
    endif()
    if(pure)
      set(pure_text "yes")
    else()
      set(pure_text "no")
    endif()
    string(APPEND table "| `${name}` | ${owns} | ${uses_text} | ${pure_text} | ${libs_text} | ${summary} |\n")
  endforeach()
  get_property(exempt GLOBAL PROPERTY MBOPT_MODULE_EXEMPT)
  if(exempt)
    string(APPEND table "\nNot scanned:")
    foreach(dir IN LISTS exempt)
      get_property(reason GLOBAL PROPERTY MBOPT_MODULE_EXEMPT_${dir})
      string(APPEND table " `${dir}/` (${reason}).")
    endforeach()
    string(APPEND table "\n")
  endif()
  set(${var} "${table}" PARENT_SCOPE)
endfunction()

# Rewrites the table of `doc` (relative to `root`) from the declaration.
function(mbopt_write_module_table root doc)
  file(READ "${root}/${doc}" text)
  string(FIND "${text}" "${MBOPT_MODULE_TABLE_BEGIN}" begin)
  string(FIND "${text}" "${MBOPT_MODULE_TABLE_END}" end)
  if(begin LESS 0 OR end LESS begin)
    message(FATAL_ERROR "${doc} has no module table markers:\n${MBOPT_MODULE_TABLE_BEGIN}\n${MBOPT_MODULE_TABLE_END}")
  endif()
  mbopt_module_table(table)
  string(SUBSTRING "${text}" 0 ${begin} head)
  string(SUBSTRING "${text}" ${end} -1 tail)
  file(WRITE "${root}/${doc}" "${head}${table}${tail}")
endfunction()

# mbopt_enforce_module_edges(): the top-level CMakeLists' call. Checks the
# tree now (fails the configure step unless MBOPT_ENFORCE_MODULE_EDGES is
# OFF), re-runs the configure step when a file or directory is added or
# removed anywhere in the tree (CMAKE_CONFIGURE_DEPENDS on the directories),
# and adds the target mbopt_module_edges, which re-checks at build time when
# a scanned file changes; mbopt_library() targets depend on it.
function(mbopt_enforce_module_edges)
  mbopt_declare_modules()
  set(doc docs/architecture.md)
  mbopt_check_module_edges(ROOT "${PROJECT_SOURCE_DIR}" DOC ${doc}
    FILES_VAR files ERRORS_VAR errors)
  mbopt_report_module_edge_errors("${errors}" ${MBOPT_ENFORCE_MODULE_EDGES})

  set(dirs "${PROJECT_SOURCE_DIR}")
  foreach(file IN LISTS files)
    get_filename_component(dir "${file}" DIRECTORY)
    while(NOT dir IN_LIST dirs AND NOT dir STREQUAL PROJECT_SOURCE_DIR)
      list(APPEND dirs "${dir}")
      get_filename_component(dir "${dir}" DIRECTORY)
    endwhile()
  endforeach()
  file(GLOB top LIST_DIRECTORIES true "${PROJECT_SOURCE_DIR}/*")
  foreach(entry IN LISTS top)
    get_filename_component(leaf "${entry}" NAME)
    if(IS_DIRECTORY "${entry}" AND NOT leaf MATCHES "^\\." AND NOT EXISTS "${entry}/CMakeFiles")
      list(APPEND dirs "${entry}")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES dirs)
  set_property(DIRECTORY "${PROJECT_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
    ${dirs} "${PROJECT_SOURCE_DIR}/${doc}")

  set(stamp "${CMAKE_BINARY_DIR}/module_edges.stamp")
  add_custom_command(OUTPUT "${stamp}"
    COMMAND "${CMAKE_COMMAND}" -DROOT=${PROJECT_SOURCE_DIR} -DSTAMP=${stamp}
            -DENFORCE=${MBOPT_ENFORCE_MODULE_EDGES} -P "${CMAKE_CURRENT_FUNCTION_LIST_FILE}"
    DEPENDS ${files} "${PROJECT_SOURCE_DIR}/${doc}" "${CMAKE_CURRENT_FUNCTION_LIST_FILE}"
    COMMENT "Checking module edges (docs/architecture.md)"
    VERBATIM)
  add_custom_target(mbopt_module_edges ALL DEPENDS "${stamp}")
endfunction()

# Script mode: cmake -DROOT=<tree> [-DDECLARATION=<file>] [-DDOC=<file>]
#   [-DWRITE_DOC_TABLE=ON] -P cmake/ModuleEdges.cmake
if(CMAKE_SCRIPT_MODE_FILE STREQUAL CMAKE_CURRENT_LIST_FILE)
  if(NOT DEFINED ROOT)
    message(FATAL_ERROR "usage: cmake -DROOT=<source tree> [-DDECLARATION=<file>] [-DWRITE_DOC_TABLE=ON] -P ${CMAKE_CURRENT_LIST_FILE}")
  endif()
  if(DEFINED DECLARATION)
    include("${DECLARATION}")
  else()
    mbopt_declare_modules()
    if(NOT DEFINED DOC)
      set(DOC docs/architecture.md)
    endif()
  endif()
  if(NOT DEFINED ENFORCE)
    set(ENFORCE ON)
  endif()
  if(WRITE_DOC_TABLE)
    mbopt_write_module_table("${ROOT}" "${DOC}")
  else()
    mbopt_check_module_edges(ROOT "${ROOT}" DOC "${DOC}" ERRORS_VAR errors)
    mbopt_report_module_edge_errors("${errors}" ${ENFORCE})
  endif()
  if(DEFINED STAMP)
    file(TOUCH "${STAMP}")
  endif()
endif()
