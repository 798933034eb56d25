# gravcal: the README's commands.
#   make demo   set up what gravcal needs to run (tools/setup.sh: R, a
#               compiler, zlib, Rcpp, RcppEigen), install, calibrate the
#               bundled example recording
#   make test   set up the test tools too (tools/setup-test.sh), R CMD
#               build + R CMD check --as-cran (all tests), the C++-driving
#               test files under ASan and UBSan, the fuzzers, the standalone
#               C++ core tests (also under valgrind), the Slurm run and the
#               site: CI's command
#   make platform-check  (not part of make test; run before resolving)
#               the Windows (mingw-w64, run under wine) and clang/libc++
#               builds (cross-check) and the build with a user's aggressive
#               compiler flags (flags-check)
#   make sanitize  (not part of make test) the whole suite under ASan and
#               UBSan, run before resolving
#   make site   the pkgdown documentation site (_build/site), checked in
#               headless Chromium
#   make test-noLD  (not part of make test) the tests that compare with
#               R's and GGIR's numbers, on an R built without long double
#   make test-Rnext  (not part of make test) the same tests on a newer R
#               (4.4 or 4.5) built from source, with GGIR 3.3-9
#   make test-arm64  the slow platform check, not part of make test (run
#               before resolving): Debian's arm64 R in a chroot under qemu,
#               GGIR from CRAN sources there, the GGIR-identity tests
R ?= R
RSCRIPT ?= Rscript
BUILD := _build
LIB := $(BUILD)/lib
SHARED_DATA ?= $(abspath ../shared/data)
GGIR_CACHE := $(abspath tests/ggir-cache)
VERSION := $(shell sed -n 's/^Version: *//p' DESCRIPTION)
TARBALL := gravcal_$(VERSION).tar.gz

# The tests' R processes ask glibc's malloc (>= 2.35; older ones ignore it)
# to advise transparent huge pages for the memory it maps. R gives a large
# vector's memory back to the kernel when it frees it, so the next one is
# fresh memory, and on a virtual machine that returns freed memory to its
# host the first write costs about 3 us for each 4 KB page: with 2 MB pages
# test-ggir.R and test-ggir-part1.R ran 1.55 times faster alone on such a
# machine, the check's whole suite beside the other lane 1.06 times
# (bench/speed-notes.md, "Fresh memory"). It changes where memory comes
# from, never a result. Set
# for make test's steps and the test targets only: bench/'s contenders run
# as users run them.
TEST_TUNABLES := glibc.malloc.hugetlb=1
# what every test run's R gets in its environment: the shared data, the
# cache of GGIR's results, testthat's off-CRAN tests, the tunable
TEST_ENV := GRAVCAL_SHARED_DATA=$(SHARED_DATA) GRAVCAL_GGIR_CACHE=$(GGIR_CACHE) NOT_CRAN=true \
            GLIBC_TUNABLES=$(TEST_TUNABLES)

# R CMD check on a machine without general network access: skip the parts
# that must reach servers other than CRAN (current-time lookup) and CRAN's
# incoming checks that need its database. NOT_CRAN=true: testthat runs
# expect_snapshot() only off CRAN, and the snapshots of every error message
# and printed fit are part of the suite.
CHECK_ENV := _R_CHECK_FUTURE_FILE_TIMESTAMPS_=FALSE _R_CHECK_SYSTEM_CLOCK_=FALSE \
             _R_CHECK_CRAN_INCOMING_REMOTE_=FALSE $(TEST_ENV)


# (test-slurm: a single-node Slurm, see below)
.PHONY: quick test-ggir-cache profile-tests profile-quick test-noLD test-Rnext test-arm64 test-part2to5 test-ggir-own test-slurm setup setup-test install demo test tarball check-run sanitize-run check core cross-check flags-check platform-check sanitize valgrind fuzz fuzz-short site document bench bench-speed bench-memory bench-files bench-formats refresh-vignettes clean

# what building and running gravcal needs, nothing more
setup:
	bash tools/setup.sh

# and what the tests need: the Suggests, GGIR, the test tools
setup-test:
	bash tools/setup-test.sh

# the package's translation units compiled in parallel, one per core (the
# longest takes about a third of the serial time)
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
# (installed once for all the targets that need it, again only when a file
# of the package changed: $(BUILD)/install.stamp)
PKG_SRC := DESCRIPTION NAMESPACE $(shell find R src inst vignettes -type f ! -name '*.o' ! -name '*.so' ! -name '*.dll' 2>/dev/null)
install: $(BUILD)/install.stamp
$(BUILD)/install.stamp: $(PKG_SRC) | setup
	mkdir -p $(LIB)
	MAKEFLAGS=-j$(JOBS) $(R) CMD INSTALL --preclean --no-multiarch -l $(LIB) . > $(BUILD)/install.log 2>&1 || (cat $(BUILD)/install.log; exit 1)
	touch $@

demo: install
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) tools/demo.R

# make test: the tarball, then two lanes side by side, one a core:
# - lane A, in the background: the sanitizer run (SANITIZE_TESTS under ASan
#   and UBSan, quick tier), installed from the tarball (so built in a
#   directory of its own), then the fuzzers for 10 s each (tests/fuzz, their
#   regressions replayed) and the core's tests (core, valgrind): the only
#   step that installs the package into $(LIB) from src/ is in this lane;
#   its output: $(BUILD)/lane-a.log;
# - lane B: R CMD check (the whole suite) of the tarball, in its own
#   directory, then the Slurm run and the site, from the check's own
#   installation (RUN_LIB).
# The two lanes take about the same time (CI's limit is 90 minutes; make
# test about 35 on 2 cores). The Windows, libc++ and aggressive flags'
# builds are make platform-check's, run before resolving with the other
# slow platform checks (CONTRIBUTING.md).
# It fails when either lane does. Each step's wall time is printed and kept
# in $(BUILD)/times.txt (tools/timed.sh). GGIR's side of the identity tests
# comes from tests/ggir-cache where the same input, parameters, GGIR version
# and platform were run before (tests/testthat/helper-ggir-cache.R; the
# check recomputes a sixteenth of the entries, those whose GGIR call took
# at most 20 s of CPU, and compares them; make test-ggir-cache all). Every
# step's R runs with TEST_TUNABLES.
#
# SANITIZE_TESTS: the test files whose tests drive the C++ core and its glue
# on device files, damaged files and bad input (the decoders, the
# segmenter, the fits, the windows, the epoch signals, GGIR part 1's store
# and meta files, interrupts), run at the quick tier. Left to make sanitize
# (the whole suite under the sanitizers, about 75 minutes on 2 cores where
# fresh memory is dear: a check before resolving an issue): the identity
# tests against GGIR on long recordings and many parameters, whose compiled
# paths these files already take, and the R-side tests (cohorts, formats of
# coefficients, plots, plausibility).
SANITIZE_TESTS := apply|bad-input|bad-input-cases|budget|calibrate|damaged|decode-csv|decode-cwa|decode-geneactiv|decode-gt3x|decode-movisens|decode-parmay|epochs|fit-ellipsoid|fit-gradient|fit-icp|ggir-part1|ggir-segments|headers|interrupt|meta-store|near-rest|points|pool|read|rest-quality|segments|selection|simd|uncertainty|windows|write-recording
TEST_LANE_A := fuzz-short core valgrind
TEST_LANE_B := test-slurm site
test: setup-test
	@rm -f $(BUILD)/times.txt; start=$$(date +%s); \
	  export GLIBC_TUNABLES="$${GLIBC_TUNABLES:+$$GLIBC_TUNABLES:}$(TEST_TUNABLES)"; \
	  bash tools/timed.sh tarball $(MAKE) tarball || exit 1; \
	  ( bash tools/timed.sh sanitize $(MAKE) sanitize-run SANITIZE_SRC=$(BUILD)/$(TARBALL) \
	      SANITIZE_FILTER='^($(SANITIZE_TESTS))$$' SANITIZE_TIER=quick || exit 1; \
	    for t in $(TEST_LANE_A); do bash tools/timed.sh $$t $(MAKE) $$t || exit 1; done ) \
	    > $(BUILD)/lane-a.log 2>&1 & lane_a=$$!; \
	  echo "test: lane A (sanitize, then $(TEST_LANE_A)) runs in the background (log: $(BUILD)/lane-a.log); lane B: check, then $(TEST_LANE_B)"; \
	  ( bash tools/timed.sh check $(MAKE) check-run || exit 1; \
	    for t in $(TEST_LANE_B); do bash tools/timed.sh $$t $(MAKE) $$t RUN_LIB=$(BUILD)/gravcal.Rcheck || exit 1; done ); b=$$?; \
	  wait $$lane_a; a=$$?; \
	  if [ $$a -ne 0 ]; then tail -80 $(BUILD)/lane-a.log; echo "test: lane A failed"; \
	  else grep -E "ASan/UBSan clean|expectations|^fuzz_|agree|passed under wine" $(BUILD)/lane-a.log; fi; \
	  echo "test: steps' wall times:"; cat $(BUILD)/times.txt; \
	  echo "test: $$(( $$(date +%s) - start )) s in all"; \
	  test $$a -eq 0 && test $$b -eq 0

# the R tests without the slow tier (GRAVCAL_TEST_TIER=quick: the tests that
# call skip_if_quick()), from the installed package, for the edit-test loop:
# a few minutes
quick: install setup-test
	cd tests/testthat && R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" \
	  $(TEST_ENV) \
	  GRAVCAL_TEST_TIER=quick $(RSCRIPT) ../../tools/run-tests.R

# every cached GGIR result recomputed and compared with the cache (and the
# missing ones added): the whole suite with GRAVCAL_GGIR_CACHE_MODE=verify,
# GGIR run on every identity case as before the cache (about 20 minutes).
# Not part of make test; run it before resolving and after a GGIR upgrade.
test-ggir-cache: install setup-test
	cd tests/testthat && R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" \
	  $(TEST_ENV) \
	  GRAVCAL_GGIR_CACHE_MODE=verify $(RSCRIPT) ../../tools/run-tests.R

# the time (wall and CPU) of each test file and of the slowest tests, into
# bench/results/test-profile.md (PROFILE_OUT); profile-quick: the same of
# make quick's tier, into bench/results/test-profile-quick.md
PROFILE_OUT ?= bench/results/test-profile.md
profile-tests: install setup-test
	cd tests/testthat && R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" \
	  $(TEST_ENV) \
	  $(RSCRIPT) ../../tools/profile-tests.R $(abspath $(PROFILE_OUT))

PROFILE_QUICK_OUT ?= bench/results/test-profile-quick.md
profile-quick: install setup-test
	cd tests/testthat && R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" \
	  $(TEST_ENV) \
	  GRAVCAL_TEST_TIER=quick $(RSCRIPT) ../../tools/profile-tests.R $(abspath $(PROFILE_QUICK_OUT))

# the header-only core alone, without R, with -Wall -Wextra -Werror: unit
# tests (double, float, fixed point), the Cortex-M4 build (no heap), the
# instruction counts, and R's fit_gradient() against it bit for bit, built
# for the host and run on an emulated Cortex-M4
core: install setup-test
	$(MAKE) -C tests/cpp test arm cost
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(MAKE) -C tests/cpp check-r check-m4

# the core and the glue where CRAN also builds them (part of make test):
# tests/cpp's core tests built for Windows with mingw-w64's g++ and run
# under wine (Windows' 32-bit long: the file over 4 GiB), and with clang and
# libc++ (as on macOS; run), -Wall -Wextra -Werror; gravcal.dll compiled
# (-O2) and linked for Windows against an import library of the R symbols it
# uses (tools/win-dll.sh: R's Windows headers and R.dll are not here, this
# R's headers stand in); src/*.cpp compiled with libc++ (syntax only: macOS's
# R is not here either; -Wno-cast-function-type for R's routine registration)
R_INCLUDE := $(shell $(RSCRIPT) -e 'cat(R.home("include"))' 2>/dev/null)
RCPP_INC := $(shell $(RSCRIPT) -e 'cat(system.file("include", package = "Rcpp"))' 2>/dev/null)
RCPPEIGEN_INC := $(shell $(RSCRIPT) -e 'cat(system.file("include", package = "RcppEigen"))' 2>/dev/null)
# (the test programs built two at a time: CROSS_JOBS)
CROSS_JOBS ?= 2
cross-check: setup-test
	$(MAKE) -j$(CROSS_JOBS) -C tests/cpp cross-check
	RSCRIPT=$(RSCRIPT) bash tools/win-dll.sh $(BUILD)/win
	@for f in src/*.cpp; do \
	  clang++ -stdlib=libc++ -std=gnu++17 -fsyntax-only -Wall -Wextra -Wno-cast-function-type -Werror \
	    -I$(R_INCLUDE) -Iinst/include -isystem $(RCPP_INC) -isystem $(RCPPEIGEN_INC) $$f || exit 1; \
	  echo "clang, libc++: $$f compiles (syntax only)"; done

# gravcal built as a user with aggressive flags in ~/.R/Makevars builds it
# (R_MAKEVARS_USER; a C++17 package is compiled with CXX17FLAGS, not
# CXXFLAGS, so both are set). g++ with -O3 -march=native (and GCC's default
# -ffp-contract=fast, said explicitly): the pin in gravcal/mcu/fp_contract.hpp
# wins, so no fused multiply-add outside Eigen's own kernels
# (tools/fma-count.sh), g.calibrate() identical to GGIR's on real files
# (tools/flags-check.R) and the core's digests those of the default build.
# clang++ with -ffp-contract=fast, which beats the pin: the load-time probe
# sees it and the GGIR-compatible entries refuse. About 5 minutes.
FLAGS_NATIVE := -O3 -march=native -ffp-contract=fast
FLAGS_CLANG := -O1 -march=native -ffp-contract=fast
# FLAGS_SRC: what is installed (default: this tree, built in src/; make test
# gives it the tarball, built in a directory of its own)
FLAGS_SRC ?= .
flags-check: setup-test
	mkdir -p $(BUILD)/lib-native $(BUILD)/lib-clang-fast
	printf 'CXX17FLAGS = $(FLAGS_NATIVE)\nCXXFLAGS = $(FLAGS_NATIVE)\n' > $(BUILD)/native.mk
	printf 'CXX17 = clang++\nCXX17FLAGS = $(FLAGS_CLANG)\nCXXFLAGS = $(FLAGS_CLANG)\n' > $(BUILD)/clang-fast.mk
	GRAVCAL_KEEP_SYMBOLS=1 R_MAKEVARS_USER=$(abspath $(BUILD)/native.mk) $(R) CMD INSTALL --preclean --no-multiarch \
	  -l $(BUILD)/lib-native $(FLAGS_SRC) > $(BUILD)/native-install.log 2>&1 || (tail -40 $(BUILD)/native-install.log; exit 1)
	sh tools/fma-count.sh $(BUILD)/lib-native/gravcal/libs/gravcal.so
	R_LIBS="$(abspath $(BUILD)/lib-native)$${R_LIBS:+:$$R_LIBS}" GRAVCAL_SHARED_DATA=$(SHARED_DATA) GRAVCAL_GGIR_CACHE=$(GGIR_CACHE) \
	  $(RSCRIPT) tools/flags-check.R bits
	$(MAKE) -C tests/cpp digest-flags DIGEST_FLAGS="$(FLAGS_NATIVE)"
	R_MAKEVARS_USER=$(abspath $(BUILD)/clang-fast.mk) $(R) CMD INSTALL --preclean --no-multiarch \
	  -l $(BUILD)/lib-clang-fast $(FLAGS_SRC) > $(BUILD)/clang-install.log 2>&1 || (tail -40 $(BUILD)/clang-install.log; exit 1)
	R_LIBS="$(abspath $(BUILD)/lib-clang-fast)$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) tools/flags-check.R refuse
	if [ "$(FLAGS_SRC)" = "." ]; then rm -f src/*.o src/*.so; fi

# the whole test suite against the package built with AddressSanitizer and
# UndefinedBehaviorSanitizer (as CRAN's gcc-ASAN check); R itself is not
# instrumented, so the runtimes are preloaded. Any report fails.
# SANITIZE_SRC: what is installed (default: this tree, built in src/; make
# test gives it the checked tarball, built in a directory of its own).
ASAN_RT = $(shell gcc -print-file-name=libasan.so) $(shell gcc -print-file-name=libubsan.so)
SANITIZE_SRC ?= .
# SANITIZE_FILTER, SANITIZE_TIER: which test files (a regular expression on
# their names, as GRAVCAL_TEST_FILTER) and which tier (as GRAVCAL_TEST_TIER);
# empty, as for make sanitize: the whole suite, full tier. make test passes
# SANITIZE_TESTS at the quick tier (see there).
SANITIZE_FILTER ?=
SANITIZE_TIER ?=
sanitize: setup-test
	$(MAKE) sanitize-run
sanitize-run:
	mkdir -p $(BUILD)/asan
	R_MAKEVARS_USER=$(abspath tools/sanitize.mk) $(R) CMD INSTALL --preclean --no-multiarch \
	  --no-test-load -l $(BUILD)/asan $(SANITIZE_SRC) > $(BUILD)/asan-install.log 2>&1 || (cat $(BUILD)/asan-install.log; exit 1)
	if [ "$(SANITIZE_SRC)" = "." ]; then rm -f src/*.o src/*.so; fi
	cd tests/testthat && LD_PRELOAD="$(ASAN_RT)" \
	  ASAN_OPTIONS=detect_leaks=0:detect_stack_use_after_return=0:abort_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1 R_LIBS="$(abspath $(BUILD)/asan)" GRAVCAL_GGIR_CACHE_MODE=trust \
	  GRAVCAL_TEST_FILTER='$(SANITIZE_FILTER)' GRAVCAL_TEST_TIER='$(SANITIZE_TIER)' \
	  GRAVCAL_SHARED_DATA=$(SHARED_DATA) GRAVCAL_GGIR_CACHE=$(GGIR_CACHE) NOT_CRAN=true $(RSCRIPT) ../../tools/run-tests.R \
	  > ../../$(BUILD)/sanitize.log 2>&1 || (tail -60 ../../$(BUILD)/sanitize.log; exit 1)
	@if grep -qE "ERROR: AddressSanitizer|runtime error:" $(BUILD)/sanitize.log; then \
	  grep -E -A20 "ERROR: AddressSanitizer|runtime error:" $(BUILD)/sanitize.log | head -60; exit 1; fi
	@tail -1 $(BUILD)/sanitize.log; echo "sanitize: ASan/UBSan clean"

# the core's unit tests under valgrind
valgrind: setup-test
	$(MAKE) -C tests/cpp valgrind

# libFuzzer harnesses (clang): FUZZ_SECONDS per harness
fuzz: setup-test
	$(MAKE) -C tests/fuzz fuzz FUZZ_SECONDS=$${FUZZ_SECONDS:-600}

fuzz-short: setup-test
	$(MAKE) -C tests/fuzz fuzz FUZZ_SECONDS=10

# the Windows, libc++ and aggressive flags' builds (see cross-check and
# flags-check): a slow platform check, before resolving; about 10 minutes
platform-check: cross-check flags-check

check: setup-test
	$(MAKE) tarball
	$(MAKE) check-run
tarball:
	mkdir -p $(BUILD)
	cd $(BUILD) && MAKEFLAGS=-j$(JOBS) $(R) CMD build --no-manual .. > build.log 2>&1 || (cat build.log; exit 1)
check-run:
	cd $(BUILD) && env $(CHECK_ENV) $(R) CMD check --as-cran --no-manual $(TARBALL) > check.log 2>&1 || true
	bash tools/check-result.sh $(BUILD)/gravcal.Rcheck

document:
	$(RSCRIPT) -e 'Rcpp::compileAttributes(); roxygen2::roxygenise()'

bench: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/table2.R

# speed and memory against GGIR (about 30 minutes; results in bench/results)
bench-speed: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/speed.R

# peak memory calibrating a 7-day device file, against GGIR (about 15 minutes)
bench-memory: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/memory.R

# end to end from device files against GGIR, each contender in its own
# process (about 30 minutes; writes about 9 GB of files once, see the script)
bench-files: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/files.R

# issue 29's formats (Parmay .bin, ad hoc csv, Axivity csv; 7 days) against
# GGIR, each contender in its own process (about an hour on a busy machine;
# writes about 8 GB of files once, see the script)
bench-formats: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) bench/formats.R

# recompute the vignettes' cached results (about 10 minutes)
refresh-vignettes: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" GRAVCAL_SHARED_DATA=$(SHARED_DATA) $(RSCRIPT) tools/refresh-vignettes.R

# the documentation site (_pkgdown.yml) from the installed package, into
# _build/site, without the network (pkgdown.internet = FALSE: no CRAN or
# Bioconductor lookups) and on at most 2 cores; then tools/site-test.R opens
# it in headless Chromium (screenshots in _build/site-shots) and fails on a
# broken internal link or a missing image
SITE_ENV := OMP_THREAD_LIMIT=2 OMP_NUM_THREADS=2 R_DATATABLE_NUM_THREADS=2 \
            MC_CORES=2 R_PARALLELLY_AVAILABLECORES_FALLBACK=2 \
            GRAVCAL_SHARED_DATA=$(SHARED_DATA)
# RUN_LIB: the library site and test-slurm run gravcal from (default: make
# install's $(LIB), installed first); make test's lane B gives them the
# check's own installation of the tarball ($(BUILD)/gravcal.Rcheck), so that
# that lane never builds in src/
RUN_LIB ?=
USE_LIB = $(abspath $(or $(RUN_LIB),$(LIB)))
site: $(if $(RUN_LIB),,install) setup-test
	rm -rf $(BUILD)/site $(BUILD)/site-shots
	env $(SITE_ENV) R_LIBS="$(USE_LIB)$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) -e \
	  'options(pkgdown.internet = FALSE, Ncpus = 2); pkgdown::build_site(install = FALSE, new_process = FALSE, preview = FALSE)' \
	  > $(BUILD)/site.log 2>&1 || (tail -60 $(BUILD)/site.log; exit 1)
	@if grep -n "^Warning\|^Error" $(BUILD)/site.log; then echo "site: pkgdown warned (see $(BUILD)/site.log)"; exit 1; fi
	R_LIBS="$(USE_LIB)$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) tools/site-test.R $(BUILD)/site $(BUILD)/site-shots

clean:
	rm -rf $(BUILD) src/*.o src/*.so gravcal-example.png

# GGIR's numbers on an R without long double (configure
# --disable-long-double, CRAN's "noLD" check; not part of make test): builds
# that R once (tools/noLD-R.sh, into GRAVCAL_NOLD_PREFIX, default
# ~/.cache/gravcal/R-noLD: about 25 minutes on 2 cores, then GGIR and the
# test packages from CRAN into its library, about 20 more) or reuses it,
# installs gravcal into it and runs the test files that compare with R's or
# GGIR's own numbers (NOLD_TESTS, tools/run-tests.R's filter)
NOLD_TESTS ?= ggir|ggir-params|ggir-interpolation|ggir-stress|ggir-getmeta|ggir-filters|ggir-part1|ggir-inspect|epochs|meta-store|fit-icp|decode-.*|windows|adhoc-csv|axivity-csv|read|simd|fp-build|noLD
# The package's sources copied to `$(1)` to install from, so that a build
# in the working tree at the same time (make install, R CMD INSTALL .)
# cannot mix its object files into another R's library
pkg_copy = rm -rf $(1) && mkdir -p $(1) && cp -R DESCRIPTION NAMESPACE LICENSE R src inst man $(1)/ && \
	rm -f $(1)/src/*.o $(1)/src/*.so $(1)/src/*.dll

test-noLD:
	@mkdir -p $(BUILD)/lib-noLD && $(call pkg_copy,$(BUILD)/src-noLD) && \
	bin=$$(bash tools/noLD-R.sh | tee $(BUILD)/noLD-R.log | tail -1) && \
	{ [ -x "$$bin/Rscript" ] || { echo "test-noLD: tools/noLD-R.sh failed (its output: $(BUILD)/noLD-R.log)" >&2; exit 1; }; } && \
	{ $$bin/R CMD INSTALL --preclean --no-multiarch -l $(BUILD)/lib-noLD $(BUILD)/src-noLD > $(BUILD)/install-noLD.log 2>&1 || \
	  { cat $(BUILD)/install-noLD.log; exit 1; }; } && \
	cd tests/testthat && R_LIBS="$(abspath $(BUILD)/lib-noLD)" R_LIBS_USER="$(abspath $(BUILD)/lib-noLD)" \
	  GRAVCAL_SHARED_DATA=$(SHARED_DATA) NOT_CRAN=true GRAVCAL_TEST_FILTER='^($(NOLD_TESTS))$$' \
	  $$bin/Rscript ../../tools/run-tests.R

# GGIR's numbers on a newer R than the system's 4.2 (GGIR behaves
# differently on R >= 4.3 in places; not part of make test): builds R 4.4.3
# once (or, where CRAN's R sources are not reachable, Debian's R 4.5.0;
# tools/Rnext-R.sh, into GRAVCAL_RNEXT_PREFIX, default
# ~/.cache/gravcal/R-next: about 5 minutes on 2 cores), with GGIR and the
# test packages from CRAN at the system library's versions (about 12 more),
# or reuses it, installs gravcal into it and runs RNEXT_TESTS. GGIR's
# results are cached per R version: the first run on that R computes them
# all, about 15 minutes (RNEXT_GGIR_CACHE, default tests/ggir-cache).
RNEXT_TESTS ?= $(NOLD_TESTS)
RNEXT_GGIR_CACHE ?= $(GGIR_CACHE)
test-Rnext:
	@mkdir -p $(BUILD)/lib-Rnext && $(call pkg_copy,$(BUILD)/src-Rnext) && \
	bin=$$(bash tools/Rnext-R.sh | tee $(BUILD)/Rnext-R.log | tail -1) && \
	{ [ -x "$$bin/Rscript" ] || { echo "test-Rnext: tools/Rnext-R.sh failed (its output: $(BUILD)/Rnext-R.log)" >&2; exit 1; }; } && \
	{ $$bin/R CMD INSTALL --preclean --no-multiarch -l $(BUILD)/lib-Rnext $(BUILD)/src-Rnext > $(BUILD)/install-Rnext.log 2>&1 || \
	  { cat $(BUILD)/install-Rnext.log; exit 1; }; } && \
	cd tests/testthat && R_LIBS="$(abspath $(BUILD)/lib-Rnext)" R_LIBS_USER="$(abspath $(BUILD)/lib-Rnext)" \
	  GRAVCAL_SHARED_DATA=$(SHARED_DATA) GRAVCAL_GGIR_CACHE=$(abspath $(RNEXT_GGIR_CACHE)) NOT_CRAN=true \
	  GRAVCAL_TEST_FILTER='^($(RNEXT_TESTS))$$' $$bin/Rscript ../../tools/run-tests.R

# calibrate_files() through future.batchtools on a real Slurm: starts a
# single-node Slurm here (root, Debian: slurm-wlm, munge) and runs a cohort
# as Slurm jobs, checking the table against a sequential run's
test-slurm: $(if $(RUN_LIB),,install) setup-test
	bash tools/slurm-setup.sh
	R_LIBS="$(USE_LIB)$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) tools/test-slurm.R

# gravcal on Linux aarch64 with a real arm64 R (tools/arm64-chroot.sh, as
# root): a Debian 12 arm64 chroot under qemu-user (in
# GRAVCAL_ARM64_ROOT, default ~/.cache/gravcal/arm64; made once), Debian's
# arm64 R and its prebuilt r-cran-* packages, GGIR installed from CRAN
# sources as tools/install-ggir.sh does, gravcal from this tree, then the
# GGIR-identity test files (ARM64_SCOPE=all: every test file; =table:
# tools/identity-table.R alone; ARM64_FILES="test-a.R ...": only those)
# with GRAVCAL_SHARED_DATA. Slow (qemu emulates every instruction): not
# part of make test; logs and timings in _build/arm64.
ARM64_SCOPE ?= identity
test-arm64:
	GRAVCAL_SHARED_DATA=$(SHARED_DATA) bash tools/arm64-chroot.sh $(ARM64_SCOPE)

# GGIR's parts 2 to 5 after gravcal's part 1 against GGIR's own parts 1 to 5
# (.cwa, .bin, .gt3x; every report csv compared cell by cell): slow (GGIR's
# whole pipeline twice per format), not part of make test; writes
# bench/results/part2to5.md and fails when a report differs.
test-part2to5: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) tools/part2to5-check.R 74 bench/results/part2to5.md

# GGIR's own unit tests that reach part 1, with gravcal's g.part1(),
# g.calibrate() and g.getmeta() in GGIR's namespace, against the same tests
# with GGIR's: needs GGIR's source tree (GGIR_SOURCE, a checkout or a git
# directory; its tests are not installed with GGIR), not part of make test;
# writes bench/results/ggir-own-tests.md and fails when a test passes with
# GGIR's part 1 only.
test-ggir-own: install setup-test
	R_LIBS="$(abspath $(LIB))$${R_LIBS:+:$$R_LIBS}" $(RSCRIPT) tools/ggir-own-tests.R bench/results/ggir-own-tests.md
