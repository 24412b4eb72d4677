# Runtime options for the sanitized build (build-asan/), sourced by tools/test --sanitize; source
# it yourself to run a build-asan binary by hand. Every finding stops the process with exit code
# 86, so a test that expects plume to exit 1 (a failed comparison) or 2 (bad input) cannot mistake
# a sanitizer report for the code it wanted.
_plume_san_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:exitcode=86:print_summary=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:exitcode=86:suppressions=$_plume_san_dir/ubsan.supp"
export LSAN_OPTIONS="suppressions=$_plume_san_dir/lsan.supp:print_suppressions=0"
unset _plume_san_dir
