# gravcal: the README's commands.
#   make demo   set up, install, calibrate the bundled example recording
#   make test   set up, R CMD build + R CMD check --as-cran (all tests),
#               then the standalone C++ core tests
R ?= R
RSCRIPT ?= Rscript
BUILD := _build
LIB := $(BUILD)/lib
SHARED_DATA ?= $(abspath ../shared/data)
VERSION := $(shell sed -n 's/^Version: *//p' DESCRIPTION)
TARBALL := gravcal_$(VERSION).tar.gz

# R CMD check on a machine without general network access: skip the parts
# that must reach servers other than CRAN (current-time lookup) and CRAN's
# incoming checks that need its database.
CHECK_ENV := _R_CHECK_FUTURE_FILE_TIMESTAMPS_=FALSE _R_CHECK_SYSTEM_CLOCK_=FALSE \
             _R_CHECK_CRAN_INCOMING_REMOTE_=FALSE \
             GRAVCAL_SHARED_DATA=$(SHARED_DATA)

.PHONY: setup install demo test check core document bench bench-speed bench-memory refresh-vignettes clean

setup:
	bash tools/setup.sh

install: setup
	mkdir -p $(LIB)
	$(R) CMD INSTALL --preclean --no-multiarch -l $(LIB) . > $(BUILD)/install.log 2>&1 || (cat $(BUILD)/install.log; exit 1)

demo: install
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) tools/demo.R

test: check core

# the header-only core alone, without R, with -Wall -Wextra -Werror: unit
# tests (double, float, fixed point), the Cortex-M4 build (no heap), the
# instruction counts, and R's fit_gradient() against it bit for bit
core: install
	$(MAKE) -C tests/cpp test arm cost
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(MAKE) -C tests/cpp check-r

check: setup
	mkdir -p $(BUILD)
	cd $(BUILD) && $(R) CMD build --no-manual .. > build.log 2>&1 || (cat build.log; exit 1)
	cd $(BUILD) && env $(CHECK_ENV) $(R) CMD check --as-cran --no-manual $(TARBALL) > check.log 2>&1 || true
	bash tools/check-result.sh $(BUILD)/gravcal.Rcheck

document:
	$(RSCRIPT) -e 'Rcpp::compileAttributes(); roxygen2::roxygenise()'

bench: install
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/table2.R

# speed and memory against GGIR (about 30 minutes; results in bench/results)
bench-speed: install
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/speed.R

# peak memory calibrating a 7-day device file, against GGIR (about 15 minutes)
bench-memory: install
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/memory.R

# recompute the vignettes' cached results (about 10 minutes)
refresh-vignettes: install
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" GRAVCAL_SHARED_DATA=$(SHARED_DATA) $(RSCRIPT) tools/refresh-vignettes.R

clean:
	rm -rf $(BUILD) src/*.o src/*.so gravcal-example.png
