//! Analysis of rendered images, above the renderer: error metrics against a reference
//! ([`metrics`]: RMSE, relMSE, bias per channel; reading images and crops to compare), used by
//! `caustic compare`, `converge`, the golden-image check and the tests.

pub mod metrics;
