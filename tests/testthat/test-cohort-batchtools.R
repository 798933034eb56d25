# calibrate_files() on a scheduler's plan: future.batchtools' local backend
# (every recording a batchtools job) gives the table of a sequential run.
# The same on a real single-node Slurm: `make test-slurm`
# (tools/slurm-setup.sh, tools/test-slurm.R).

test_that("a cohort under future.batchtools gives the sequential table", {
  skip_if_quick()
  skip_if_not_installed("future.batchtools")
  dir <- tempfile("batchtools")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  for (i in 1:3) {
    saveRDS(simulate_recording(hours = 8, sf = 5, seed = 400 + i),
            file.path(dir, sprintf("p%02d.rds", i)))
  }
  writeLines(c("x,y,z", "a,b,c"), file.path(dir, "p04.csv"))
  strip <- function(tab) {
    attr(tab, "fits") <- NULL
    tab$seconds <- NULL
    tab
  }
  seq_tab <- calibrate_files(dir, "lightweight", outdir = file.path(dir, "seq"))
  # the job registries go to a temporary folder, not the working directory
  old_opt <- options(future.cache.path = file.path(dir, "registries"))
  old <- future::plan("list")
  on.exit({
    future::plan(old)
    options(old_opt)
  }, add = TRUE, after = FALSE)
  future::plan(future.batchtools::batchtools_local)
  bt_tab <- calibrate_files(dir, "lightweight", outdir = file.path(dir, "bt"))
  expect_identical(strip(bt_tab), strip(seq_tab))
  expect_identical(bt_tab$status[4], "failed")
  expect_false(dir.exists(file.path(dir, "bt", ".gravcal", "lock")))
})
