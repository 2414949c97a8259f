# Sourced by the scripts here: builds the release binary and sets $caustic to its path, wherever
# cargo puts it (CARGO_TARGET_DIR, `build.target-dir` in a cargo config, or ./target), as
# `cargo metadata` reports it. Expects the working directory to be the repository root.
# With CAUSTIC_BIN set (the docs' command test sets it), that binary is used and nothing is built.
if [ -n "${CAUSTIC_BIN:-}" ]; then
  caustic=$CAUSTIC_BIN
  return 0
fi
cargo build --release --quiet --bin caustic
target_dir=$(cargo metadata --format-version 1 --no-deps | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
caustic="${target_dir:-target}/release/caustic"
if [ ! -x "$caustic" ]; then
  echo "error: no caustic binary at \`$caustic\` after \`cargo build --release\`" >&2
  exit 1
fi
