library(testthat)
library(gravcal)

test_check("gravcal")
