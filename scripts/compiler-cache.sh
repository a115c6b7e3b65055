# Sourced by the build scripts: sets `compiler_cache_args` to the CMake arguments that put ccache
# in front of the compiler when it is installed (scripts/install-deps.sh installs it), so that a
# build of the same sources in another checkout (CI's fresh clone, a worktree) reuses the objects.
# Precompiled headers are then off: they hold absolute paths, which differ between checkouts, so
# no object compiled with one could be reused. Paths under the checkout's parent folder are
# hashed relative to it (CCACHE_BASEDIR), and the working folder is not hashed.
compiler_cache_args=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}
  export CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-true}
  compiler_cache_args=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DIMSCAL_PCH=OFF)
fi
