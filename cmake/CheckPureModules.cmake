# The numerical core stays pure: the SLP core, the LP interface and the
# simulation engine may not include gRPC, Protobuf, SQLite or CLP headers, nor
# generated *.pb.h files, nor threads. Debian installs those headers in
# /usr/include, where any target could reach them, so the link graph alone
# cannot stop an include: this scan does, at configure time.
set(MBOPT_PURE_DIRS
  common
  spec
  server/slp
  server/lp
  worker/scene
  worker/model
  worker/solve)
set(MBOPT_FORBIDDEN_INCLUDE_REGEX
  "#[ \t]*include[ \t]*[<\"](grpc|grpcpp|google/protobuf|sqlite3|coin/|Clp|Coin|thread|mutex|condition_variable|future)[^>\"]*[>\"]|\\.pb\\.h")

function(mbopt_check_pure_modules)
  foreach(dir IN LISTS MBOPT_PURE_DIRS)
    file(GLOB_RECURSE files ${PROJECT_SOURCE_DIR}/${dir}/*.h ${PROJECT_SOURCE_DIR}/${dir}/*.cc)
    foreach(f IN LISTS files)
      # CLP's adapter is the one file allowed to include ClpSimplex;
      # spec/io is the boundary where text-format files become domain types.
      if(f MATCHES "clp_lp_solver\\.(h|cc)$" OR f MATCHES "/spec/io/")
        continue()
      endif()
      file(STRINGS ${f} lines REGEX "${MBOPT_FORBIDDEN_INCLUDE_REGEX}")
      if(lines)
        message(FATAL_ERROR "Pure module ${dir} includes a forbidden header in ${f}: ${lines}")
      endif()
    endforeach()
  endforeach()
endfunction()
