//! Analysis of rendered images, above the renderer: error metrics against a reference
//! ([`metrics`]: RMSE, relMSE, bias per channel; reading images and crops to compare), used by
//! `caustic compare`, `converge`, the golden-image check and the tests; the false-colour error
//! image ([`error_image`]); an integrator's error against time ([`convergence`]), the
//! convergence-slope fit ([`slope`]) and the log-log plot of error against time
//! ([`convergence_plot`], its PNG text drawn by [`plot_backend`] with the bitmap font of
//! [`pixel_font`]).

pub mod convergence;
pub mod convergence_plot;
pub mod error_image;
pub mod metrics;
pub mod pixel_font;
pub mod plot_backend;
pub mod slope;
