#' gravcal: auto-calibration of triaxial accelerometers against gravity
#'
#' gravcal finds the rest periods of a raw accelerometer recording and fits
#' calibration coefficients from them. Start with [calibrate()]; the steps
#' are [rest_windows()], [select_points()] and [fit_gradient()];
#' [apply_calibration()] corrects the samples.
#'
#' The numeric core is header-only C++ in `inst/include/gravcal` with no R
#' dependency, usable in firmware.
#' @keywords internal
#' @useDynLib gravcal, .registration = TRUE
#' @importFrom Rcpp evalCpp
"_PACKAGE"
