# calibrate_files() on a real Slurm (one node, tools/slurm-setup.sh) through
# future.batchtools: every recording a Slurm job, the table equal to a
# sequential run's. Run by `make test-slurm`; prints "N passed, N failed".
library(gravcal)
stopifnot(requireNamespace("future.batchtools", quietly = TRUE),
          nzchar(Sys.which("sbatch")))
root <- tempfile("slurm-cohort")
dir.create(root)
on.exit(unlink(root, recursive = TRUE))
study <- file.path(root, "raw")
dir.create(study)
for (i in 1:4) {
  saveRDS(simulate_recording(hours = 8, sf = 5, seed = 500 + i),
          file.path(study, sprintf("p%02d.rds", i)))
}
writeLines(c("x,y,z", "a,b,c"), file.path(study, "p05.csv"))
strip <- function(tab) {
  attr(tab, "fits") <- NULL
  tab$seconds <- NULL
  tab
}
seq_tab <- calibrate_files(study, "lightweight", outdir = file.path(root, "seq"))
options(future.cache.path = file.path(root, "registries"))
template <- "tools/slurm.tmpl"  # run from the package's root, as make does
if (!file.exists(template)) stop("run from gravcal's source folder: no ", template)
template <- normalizePath(template)
future::plan(future.batchtools::batchtools_slurm, template = template,
             resources = list(walltime = 600, memory = 1024, ncpus = 1),
             workers = 4)
t0 <- Sys.time()
slurm_tab <- calibrate_files(study, "lightweight", outdir = file.path(root, "slurm"))
future::plan(future::sequential)
cat(sprintf("slurm: %d recordings in %.1f s\n", nrow(slurm_tab),
            as.numeric(difftime(Sys.time(), t0, units = "secs"))))
checks <- c(
  "same table as a sequential run" = identical(strip(slurm_tab), strip(seq_tab)),
  "four calibrated, one failed" = identical(slurm_tab$status == "failed",
                                            c(FALSE, FALSE, FALSE, FALSE, TRUE)),
  "results in outdir" = file.exists(file.path(root, "slurm", "calibration.csv")),
  "lock released" = !dir.exists(file.path(root, "slurm", ".gravcal", "lock")))
for (n in names(checks)) cat(if (checks[[n]]) "ok    " else "FAIL  ", n, "\n", sep = "")
cat(sprintf("%d passed, %d failed\n", sum(checks), sum(!checks)))
if (!all(checks)) quit(status = 1)
