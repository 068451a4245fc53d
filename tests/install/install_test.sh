#!/usr/bin/env bash
# install_test.sh CMAKE BUILD_DIR SOURCE_DIR LIBDIR VERSION CC [FC]
# Installs BUILD_DIR into a temporary prefix and checks what a simulation developer uses from it:
# the installed tools run from the prefix (relative RPATH), pkg-config and insitu-config agree
# with the build, examples/makefile/ builds the C and (given FC) Fortran heat examples with each
# of them, a CMake project finds insitu::insitu_c and insitu::insitu_fortran, and every program
# writes an archive with a manifest. The Makefile is the installed one
# (share/insitu/examples/makefile/, with the example sources beside it). Given
# INSITU_TEST_MPI_PROGRAMS (heat_c_mpi, heat_fortran_mpi) and INSITU_TEST_MPIEXEC (mpiexec -n 2
# ...), the MPI examples are built by the plain CC and FC from insitu-mpi.pc,
# insitu-mpi-fortran.pc and insitu-config --mpi alone, and run. Fails, rather than skips, when
# make or pkg-config is missing (scripts/setup installs both).
# With INSITU_PYTHON set (the interpreter the Python module was built for), the module installed
# into the prefix, at the path the install prints, imports with that path on PYTHONPATH and opens
# the C example's archive.
set -euo pipefail
if [ $# -lt 6 ] || [ $# -gt 7 ]; then
  echo "usage: install_test.sh CMAKE BUILD_DIR SOURCE_DIR LIBDIR VERSION CC [FC]" >&2
  exit 2
fi
cmake=$1 build_dir=$2 source_dir=$3 libdir=$4 version=$5 cc=$6 fc=${7:-}
for tool in make pkg-config readelf; do
  if ! command -v "$tool" >/dev/null; then
    echo "install_test: $tool not found (scripts/setup installs it)" >&2
    exit 1
  fi
done

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
fail() {
  echo "install_test: $*" >&2
  exit 1
}
# Runs a command quietly; on failure shows its output and stops.
quietly() {
  local log="$work/command.log"
  if ! "$@" >"$log" 2>&1; then
    cat "$log" >&2
    fail "failed: $*"
  fi
}

quietly "$cmake" --install "$build_dir" --prefix "$prefix"
cp "$work/command.log" "$work/install.log"
# No library path from the environment: what runs must find libinsitu through its own RPATH.
unset LD_LIBRARY_PATH

for tool in insitu-render insitu-view insitu-capture; do
  readelf -d "$prefix/bin/$tool" | grep -q 'R.*PATH.*\$ORIGIN' ||
    fail "$tool: no RPATH relative to \$ORIGIN"
  quietly "$prefix/bin/$tool" --help
done

export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
[ "$(pkg-config --modversion insitu)" = "$version" ] || fail "insitu.pc: version is not $version"
[ "$("$prefix/bin/insitu-config" --version)" = "$version" ] || fail "insitu-config --version"
[ "$("$prefix/bin/insitu-config" --prefix)" = "$prefix" ] || fail "insitu-config --prefix"
[ "$(pkg-config --variable=prefix insitu)" = "$prefix" ] || fail "insitu.pc: prefix"
[ -f "$prefix/share/insitu/fortran/insitu.f90" ] || fail "share/insitu/fortran/insitu.f90 missing"

programs=(heat_c)
if [ -n "$fc" ]; then
  programs+=(heat_fortran)
else
  echo "install_test: built without a Fortran compiler: the C example only"
fi

# run_programs DIR: runs each program of DIR for 10 steps (one stored: "every": 10) into an
# archive of its own and checks the archive's manifest.
run_programs() {
  local dir=$1 program
  for program in "${programs[@]}"; do
    quietly "$dir/$program" "$dir/$program.cdb" 10
    [ -s "$dir/$program.cdb/manifest.json" ] || fail "$dir/$program.cdb/manifest.json missing"
  done
}

makefile="$prefix/share/insitu/examples/makefile/Makefile"
[ -f "$makefile" ] || fail "share/insitu/examples/makefile/Makefile missing"
mkdir "$work/pkg-config" "$work/insitu-config"
quietly make -C "$work/pkg-config" -f "$makefile" CC="$cc" FC="$fc" "${programs[@]}"
run_programs "$work/pkg-config"
quietly make -C "$work/insitu-config" -f "$makefile" CC="$cc" FC="$fc" \
  INSITU_CONFIG="$prefix/bin/insitu-config" "${programs[@]}"
run_programs "$work/insitu-config"

# The MPI examples, linked by the plain compilers (MPICC=CC): every flag, MPI's included, comes
# from the installed files; run at 2 ranks, rank 0 writes the archive.
read -r -a mpi_programs <<<"${INSITU_TEST_MPI_PROGRAMS:-}"
read -r -a mpiexec <<<"${INSITU_TEST_MPIEXEC:-}"
if [ ${#mpi_programs[@]} -gt 0 ]; then
  for pc in insitu-mpi insitu-mpi-fortran; do
    if [[ $pc == *fortran && ${#mpi_programs[@]} -lt 2 ]]; then continue; fi
    [ "$(pkg-config --modversion "$pc")" = "$version" ] || fail "$pc.pc: version is not $version"
  done
  for dir in pkg-config insitu-config; do
    config=()
    if [ "$dir" = insitu-config ]; then config=(INSITU_CONFIG="$prefix/bin/insitu-config"); fi
    quietly make -C "$work/$dir" -f "$makefile" MPICC="$cc" MPIFC="$fc" "${config[@]}" \
      "${mpi_programs[@]}"
    for program in "${mpi_programs[@]}"; do
      quietly "${mpiexec[@]}" "$work/$dir/$program" "$work/$dir/$program.cdb" 10
      [ -s "$work/$dir/$program.cdb/proxies/step000010_view0.exr" ] ||
        fail "$work/$dir/$program.cdb: no proxy of step 10"
    done
  done
  echo "install_test: ${mpi_programs[*]} linked by $cc${fc:+ and $fc} from insitu-mpi.pc and" \
       "insitu-config --mpi, run by ${mpiexec[*]}"
fi

consumer=(-S "$source_dir/tests/install/consumer" -B "$work/cmake" -DCMAKE_C_COMPILER="$cc"
          -DCMAKE_PREFIX_PATH="$prefix" -DEXAMPLES="$source_dir/examples")
if [ -n "$fc" ]; then consumer+=(-DCMAKE_Fortran_COMPILER="$fc"); fi
quietly "$cmake" "${consumer[@]}"
quietly "$cmake" --build "$work/cmake"
run_programs "$work/cmake"
if [ -n "${INSITU_PYTHON:-}" ]; then
  site=$(sed -n 's/.*insitu: Python module in \(.*\) (PYTHONPATH.*/\1/p' "$work/install.log")
  [ -n "$site" ] || fail "cmake --install printed no path for the Python module"
  quietly env PYTHONPATH="$site" "$INSITU_PYTHON" -c '
import os, sys, insitu
prefix, archive = sys.argv[1:]
assert os.path.realpath(insitu.__file__).startswith(os.path.realpath(prefix)), insitu.__file__
assert os.path.exists(os.path.join(os.path.dirname(insitu.__file__), "insitu.pyi"))
a = insitu.open(archive)
assert a.steps == [10] and a.fields, (a.steps, a.fields)
assert a.proxies(10)["attenuation"].max() > 0
' "$prefix" "$work/pkg-config/heat_c.cdb"
  echo "install_test: insitu (Python) imported from $site and opened an archive"
fi
echo "install_test: ${programs[*]} built and run from $prefix by make (pkg-config, insitu-config)"\
     "and by CMake"
