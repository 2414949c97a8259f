#!/usr/bin/env bash
# Regenerates the bath scene's models, assets/duck.obj, assets/boat.obj and assets/faucet.obj,
# from the implicit surfaces in examples/make_models/models.rs (meshed by surface nets, then checked: closed,
# consistently wound outwards, no degenerate or inverted triangles). Deterministic: the test
# `cargo test --release --test it models` fails until the committed files match it again.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release --quiet --example make_models
