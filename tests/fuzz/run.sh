#!/usr/bin/env bash
# Runs every fuzz target of tests/fuzz for a bounded time (what `make fuzz` calls).
#   tests/fuzz/run.sh BUILD_DIR SECONDS [TARGET...]
# BUILD_DIR is a tree configured with -DDERMIS_FUZZ=ON and built (`--target dermis-fuzz`).
# Each target runs for SECONDS (-max_total_time) on BUILD_DIR/corpus/<target> — the seeds of
# seeds.py copied there, plus whatever earlier runs added — with its dictionary, at most
# FUZZ_RSS_MB of memory (default 2048), FUZZ_TIMEOUT seconds per input (default 10), inputs of
# at most 256 KB (glTF) or 32 KB (images). Leaks inside OpenImageIO itself (tests/lsan.supp) are
# not ours and are not reported.
# A crash, sanitizer report, leak, timeout or out-of-memory stops that target and leaves the
# input in BUILD_DIR/artifacts/ (crash-*, leak-*, timeout-*, oom-*); the script then goes on with
# the other targets and exits 1 at the end. Logs: BUILD_DIR/fuzz-logs/<target>.log.
# Reproduce one input: BUILD_DIR/tests/fuzz/<target> FILE.
#
# Leaks are found per input (libFuzzer checks after any input that allocated more than it freed),
# not once more at exit: loading OpenImageIO starts log4cplus's threads in a library constructor,
# and they exit while LeakSanitizer's exit-time check suspends threads, which can crash its tracer
# ("Tracer caught signal 11 … LeakSanitizer has encountered a fatal error", an empty input) — a
# failure of the tool, not a finding. Should the tracer still fail during a run, that target runs
# once more (a leak or crash it finds then fails the run as usual).
set -uo pipefail
here="$(cd "$(dirname "$0")/../.." && pwd)"
build="$1"
seconds="$2"
shift 2
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(gltf_fuzz image_fuzz scene_fuzz)
models="${DERMIS_TEST_MODELS:-$here/tests/models}"
if [ ! -d "$models" ]; then
  echo "fuzz: $models is missing (the glTF seeds come from it)" >&2
  exit 1
fi

python3 "$here/tests/fuzz/seeds.py" "$here" "$models" "$build/corpus" || exit 1
mkdir -p "$build/artifacts" "$build/fuzz-logs"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:leak_check_at_exit=0:allocator_may_return_null=1}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$here/tests/lsan.supp}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
failed=()
for t in "${targets[@]}"; do
  dict="$here/tests/fuzz/${t%_fuzz}.dict"
  args=(-max_total_time="$seconds" -rss_limit_mb="${FUZZ_RSS_MB:-2048}"
        -timeout="${FUZZ_TIMEOUT:-10}" -artifact_prefix="$build/artifacts/$t-"
        -print_final_stats=1)
  [ -f "$dict" ] && args+=(-dict="$dict")
  # glTF inputs up to 256 KB: the small models (and their textured and .gltf forms) whole; images
  # up to 32 KB: the tiny PNG/BMP/TGA seeds whole, the 512² patterns and model textures cut
  # (decoding one under ASan takes ~0.3 s: a run would try a few inputs a second, not hundreds).
  case "$t" in
    gltf_fuzz) args+=(-max_len=262144) ;;
    image_fuzz) args+=(-max_len=32768) ;;
  esac
  echo "fuzz: $t for ${seconds} s (log: $build/fuzz-logs/$t.log)"
  ok=0
  for attempt in 1 2; do
    if "$build/tests/fuzz/$t" "${args[@]}" "$build/corpus/$t" >"$build/fuzz-logs/$t.log" 2>&1; then
      ok=1
      break
    fi
    # The tool's own failure (no report of ours in the log): once more, then it counts.
    if [ "$attempt" = 1 ] && grep -q "LeakSanitizer has encountered a fatal error" "$build/fuzz-logs/$t.log" &&
       ! grep -qE "ERROR: (AddressSanitizer|LeakSanitizer: detected|libFuzzer)|runtime error:" \
         "$build/fuzz-logs/$t.log"; then
      echo "fuzz: $t: LeakSanitizer's tracer failed (not a finding); running it once more" >&2
      cp "$build/fuzz-logs/$t.log" "$build/fuzz-logs/$t.tracer-failure.log"
      continue
    fi
    break
  done
  if [ "$ok" = 1 ]; then
    grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb|^#[0-9]+.*DONE" \
      "$build/fuzz-logs/$t.log" | sed "s/^/fuzz: $t: /"
  else
    echo "fuzz: $t FAILED — last lines of its log:" >&2
    tail -n 40 "$build/fuzz-logs/$t.log" >&2
    failed+=("$t")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: failed: ${failed[*]} (inputs in $build/artifacts/)" >&2
  exit 1
fi
echo "fuzz: no crash, leak or timeout in ${targets[*]}"
