#!/usr/bin/env bash
# CI's bounded cargo-fuzz run (issue 6 item 4; fuzz/README.md, "CI"), called by .ci/run.
#
# 1. Installs cargo-fuzz, pinned, if the right version is missing.
# 2. Builds the five targets once (flags below; measured times in fuzz/README.md).
# 3. Fuzzes each target for FUZZ_SECONDS (22 s: five targets, under 2 minutes in all) from a temporary copy of
#    the committed corpus (so a run never adds files to fuzz/corpus), with a fixed libFuzzer seed.
# 4. Fails if a target finds a crash, a timeout (an input running past FUZZ_INPUT_TIMEOUT) or an
#    out-of-memory (past 2048 MiB), naming the artifact and the command that replays it. Install
#    and build failures fail too: this step is never skipped silently.
#
# Environment (all optional): FUZZ_SECONDS, FUZZ_SEED, FUZZ_INPUT_TIMEOUT; CARGO_FUZZ_ROOT, a
# `cargo install --root` to install cargo-fuzz into (and use from) instead of cargo's default
# (how the fresh-install time in fuzz/README.md was measured without touching the machine's copy).
set -euo pipefail

CARGO_FUZZ_VERSION=0.13.2
TARGETS=(ray_file collage layers gltf obj)
FUZZ_SECONDS=${FUZZ_SECONDS:-22}
FUZZ_SEED=${FUZZ_SEED:-20260611}
FUZZ_INPUT_TIMEOUT=${FUZZ_INPUT_TIMEOUT:-10}
# Build flags, chosen by measurement (fuzz/README.md): release optimisation with debug assertions
# and overflow checks (they found the tobj overflow), without AddressSanitizer (the code under
# test is safe Rust; ASan costs build time and executions).
BUILD_FLAGS=(--release --debug-assertions --sanitizer none)
TRIPLE=x86_64-unknown-linux-gnu

fail() {
  echo "fuzz/ci.sh: FAILED: $*" >&2
  exit 1
}

cd "$(dirname "$0")"
FUZZ_DIR=$(pwd)
[ -f Cargo.toml ] && [ -d corpus ] || fail "run from a checkout: $FUZZ_DIR has no Cargo.toml and corpus/"

# ---- 1. cargo-fuzz, pinned ------------------------------------------------------------------
# Cargo looks for subcommands in $CARGO_HOME/bin before PATH, so the binary is called directly
# (`cargo-fuzz fuzz ARGS` is what `cargo fuzz ARGS` runs).
if [ -n "${CARGO_FUZZ_ROOT:-}" ]; then
  cargo_fuzz="$CARGO_FUZZ_ROOT/bin/cargo-fuzz"
  install_root=(--root "$CARGO_FUZZ_ROOT")
else
  cargo_fuzz=$(command -v cargo-fuzz || echo "${CARGO_HOME:-$HOME/.cargo}/bin/cargo-fuzz")
  install_root=()
fi
have=$("$cargo_fuzz" fuzz --version 2>/dev/null || true)
if [ "$have" != "cargo-fuzz $CARGO_FUZZ_VERSION" ]; then
  echo "== installing cargo-fuzz $CARGO_FUZZ_VERSION (found: ${have:-none})"
  start=$SECONDS
  cargo install cargo-fuzz --version "$CARGO_FUZZ_VERSION" --locked "${install_root[@]}" ||
    fail "could not install cargo-fuzz $CARGO_FUZZ_VERSION (network or toolchain problem; see above)"
  [ -n "${CARGO_FUZZ_ROOT:-}" ] || cargo_fuzz="${CARGO_HOME:-$HOME/.cargo}/bin/cargo-fuzz"
  have=$("$cargo_fuzz" fuzz --version 2>/dev/null || true)
  [ "$have" = "cargo-fuzz $CARGO_FUZZ_VERSION" ] ||
    fail "installed cargo-fuzz, but $cargo_fuzz reports '${have:-nothing}'"
  echo "== installed $have in $((SECONDS - start)) s"
fi
echo "== using $have ($cargo_fuzz)"

# ---- 2. build -------------------------------------------------------------------------------
# cargo-fuzz needs nightly rustc flags (-Zsanitizer & co.); RUSTC_BOOTSTRAP=1 lets the stable
# toolchain accept them.
export RUSTC_BOOTSTRAP=1
echo "== building ${TARGETS[*]} (${BUILD_FLAGS[*]})"
start=$SECONDS
"$cargo_fuzz" fuzz build --fuzz-dir "$FUZZ_DIR" "${BUILD_FLAGS[@]}" ||
  fail "could not build the fuzz targets (see the compiler output above)"
echo "== built in $((SECONDS - start)) s"
# fuzz/Cargo.lock is committed: a build that had to change it means the lock file is stale.
if git -C "$FUZZ_DIR" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  git -C "$FUZZ_DIR" diff --quiet -- Cargo.lock ||
    fail "the build changed fuzz/Cargo.lock; commit the updated lock file"
fi

# ---- 3. fuzz --------------------------------------------------------------------------------
work=$(mktemp -d "${TMPDIR:-/tmp}/mcctrace-fuzz-ci.XXXXXX")
trap 'rm -rf "$work"' EXIT
logs="$FUZZ_DIR/target/fuzz-ci-logs"
mkdir -p "$logs"
failed=()
summary=()
for target in "${TARGETS[@]}"; do
  binary="$FUZZ_DIR/target/$TRIPLE/release/$target"
  [ -x "$binary" ] || fail "the build did not produce $binary"
  cp -R "corpus/$target" "$work/$target"
  mkdir -p "artifacts/$target"
  args=(
    "$work/$target"
    -seed="$FUZZ_SEED"
    -max_total_time="$FUZZ_SECONDS"
    -timeout="$FUZZ_INPUT_TIMEOUT"
    -rss_limit_mb=2048
    -print_final_stats=1
    -artifact_prefix="$FUZZ_DIR/artifacts/$target/"
  )
  [ -f "dict/$target.dict" ] && args+=(-dict="$FUZZ_DIR/dict/$target.dict")
  echo "== fuzzing $target for $FUZZ_SECONDS s (seed $FUZZ_SEED; log: $logs/$target.log)"
  start=$SECONDS
  status=0
  "$binary" "${args[@]}" >"$logs/$target.log" 2>&1 || status=$?
  elapsed=$((SECONDS - start))
  execs=$(sed -n 's/^stat::number_of_executed_units: *\([0-9]*\).*/\1/p' "$logs/$target.log" | tail -n 1)
  corpus_size=$(find "$work/$target" -type f | wc -l)
  if [ "$status" -ne 0 ]; then
    artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$logs/$target.log" | tail -n 1)
    echo "---- last lines of $logs/$target.log" >&2
    tail -n 40 "$logs/$target.log" >&2
    echo "----" >&2
    echo "$target FOUND A PROBLEM (libFuzzer exit status $status) after ${execs:-?} executions." >&2
    if [ -n "$artifact" ]; then
      echo "  input: $artifact" >&2
      echo "  replay: cd fuzz && RUSTC_BOOTSTRAP=1 cargo fuzz run ${BUILD_FLAGS[*]} $target $artifact" >&2
    else
      echo "  libFuzzer wrote no artifact; see the log above" >&2
    fi
    failed+=("$target")
    summary+=("$target: FAILED (status $status) after ${execs:-?} executions in $elapsed s")
  else
    [ -n "$execs" ] ||
      fail "$target: libFuzzer printed no stat::number_of_executed_units (see $logs/$target.log)"
    summary+=("$target: $execs executions in $elapsed s, corpus $corpus_size inputs after, no crash")
  fi
done

echo "== fuzzing summary"
printf '  %s\n' "${summary[@]}"
if [ "${#failed[@]}" -ne 0 ]; then
  fail "libFuzzer found problems in: ${failed[*]}" \
    "(artifacts in $FUZZ_DIR/artifacts/; fuzz/README.md, 'Reproducing a crash', says what next)"
fi
