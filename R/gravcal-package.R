#' gravcal: auto-calibration of triaxial accelerometers against gravity
#'
#' gravcal finds the rest periods of a raw accelerometer recording and fits
#' calibration coefficients from them. Start with [calibrate()]; the steps
#' are [rest_windows()], [select_points()] and [fit_gradient()];
#' [apply_calibration()] corrects the samples.
#'
#' The numeric core is header-only C++ in `inst/include/gravcal` with no R
#' dependency, usable in firmware.
#'
#' @section Speed on x86 processors:
#' The device-file decoders and the window statistics have AVX2 versions,
#' used when the processor has AVX2. They give the same results, to the
#' last bit, as the baseline versions, which every x86-64 processor runs.
#' Set the environment variable `GRAVCAL_NO_AVX2=1` before gravcal is first
#' used in an R session to run the baseline versions only (for comparisons,
#' or to rule the AVX2 versions out when chasing a problem).
#' @section Threads:
#' [g.getmeta()], [g.part1()] and [epoch_signals()] use two threads (the
#' running medians of GGIR's angles beside the other epoch signals), with
#' the same results as one. `options(gravcal.threads = 1)` keeps them to
#' one. Cohort runs on a plan with several workers keep each worker to one.
#' The second thread also inflates a `.gt3x` file's data ahead of its
#' decoder, wherever gravcal reads one, and in the GGIR method's pass
#' ([g.calibrate()], `calibrate(method = "ggir")`) takes the 10 s windows'
#' sums of each hour while the decoder reads the next (the same option
#' turns both off; the windows are the same).
#' @keywords internal
#' @useDynLib gravcal, .registration = TRUE
#' @importFrom Rcpp evalCpp
"_PACKAGE"
