# Recomputes the cached results of the two vignettes that reproduce the
# papers (vignettes/farago2024-table3.rds, vignettes/vanhees2014-cohort.rds):
# it renders them with GRAVCAL_REFRESH_VIGNETTES=true, which runs the chunks
# that compute (eval = refresh) and saves their results beside the .Rmd.
# Needs gravcal installed, and DEoptim, signal and GGIR; the agcounts
# recording is taken from the agcounts package when it is installed, else
# from ../shared/data/agcounts (GRAVCAL_SHARED_DATA). About 10 minutes.
#   Rscript tools/refresh-vignettes.R      (or `make refresh-vignettes`)
Sys.setenv(GRAVCAL_REFRESH_VIGNETTES = "true")
if (!nzchar(Sys.getenv("GRAVCAL_SHARED_DATA"))) {
  Sys.setenv(GRAVCAL_SHARED_DATA = normalizePath(file.path("..", "shared", "data"),
                                                 mustWork = FALSE))
}
for (p in c("rmarkdown", "DEoptim", "signal", "gravcal")) {
  if (!requireNamespace(p, quietly = TRUE)) stop("refresh-vignettes: package ", p, " is needed")
}
owd <- setwd("vignettes")
on.exit(setwd(owd))
for (f in c("farago2024.Rmd", "vanhees2014.Rmd")) {
  message("refreshing ", f)
  rmarkdown::render(f, output_dir = tempdir(), quiet = TRUE)
}
