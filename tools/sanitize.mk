# R_MAKEVARS_USER for `make sanitize`: the package's C++ built with
# AddressSanitizer and UndefinedBehaviorSanitizer, as CRAN's gcc-ASAN check
# builds it (any UBSan report is an error).
CXX17FLAGS = -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
CXXFLAGS = -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
LDFLAGS = -fsanitize=address,undefined
