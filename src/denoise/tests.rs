//! Tests of the denoiser.
