# A JSON reader for the coefficient files of other tools (R/coef-tools.R):
# RFC 8259 JSON, plus the three words Python's json module writes for
# numbers JSON has no text for (NaN, Infinity, -Infinity), which actipy's
# and the UK Biobank pipeline's files hold where a value is missing. The
# files are small (a few kilobytes), so the reader is written for clarity:
# a tokenizer by regular expression, then a recursive descent over the
# tokens.
#
# Values: an object is a named list, an array a list (json_value() flattens
# what the readers need), a string a character string, a number a double
# (NaN, Inf, -Inf for Python's words), true and false logical, null NA.

json_token_re <- paste0(
  "\"(?:[^\"\\\\]|\\\\.)*\"",                                # string
  "|-?(?:Infinity|(?:0|[1-9][0-9]*)(?:\\.[0-9]+)?(?:[eE][+-]?[0-9]+)?)", # number
  "|NaN|true|false|null",                                  # words
  "|[][{}:,]",                                             # punctuation
  "|[^][{}:,\\s\"]+|\"")                                   # anything else: an error

# The value of the JSON text `text` (read from the file `f`, named in errors).
json_parse <- function(text, f) {
  tok <- regmatches(text, gregexpr(json_token_re, text, perl = TRUE))[[1]]
  bad <- function(what) {
    abort("`file`: \"", f, "\" is not valid JSON: ", what, ".")
  }
  i <- 0L
  n <- length(tok)
  peek <- function() if (i < n) tok[i + 1L] else ""
  take <- function() {
    if (i >= n) bad("it ends before its last value is complete")
    i <<- i + 1L
    tok[i]
  }
  expect <- function(t) {
    got <- take()
    if (!identical(got, t)) bad(paste0("\"", t, "\" expected, \"", got, "\" found"))
  }
  value <- function() {
    t <- take()
    first <- substr(t, 1L, 1L)
    if (t == "{") {
      out <- list()
      keys <- character(0)
      if (peek() == "}") {
        take()
        return(stats::setNames(out, keys))
      }
      repeat {
        k <- take()
        if (substr(k, 1L, 1L) != "\"" || nchar(k) < 2L) {
          bad(paste0("a key (a string) expected, \"", k, "\" found"))
        }
        expect(":")
        out[length(out) + 1L] <- list(value())
        keys <- c(keys, json_unescape(k, bad))
        sep <- take()
        if (sep == "}") break
        if (sep != ",") bad(paste0("\",\" or \"}\" expected, \"", sep, "\" found"))
      }
      return(stats::setNames(out, keys))
    }
    if (t == "[") {
      out <- list()
      if (peek() == "]") {
        take()
        return(out)
      }
      repeat {
        out[length(out) + 1L] <- list(value())
        sep <- take()
        if (sep == "]") break
        if (sep != ",") bad(paste0("\",\" or \"]\" expected, \"", sep, "\" found"))
      }
      return(out)
    }
    if (first == "\"") {
      if (nchar(t) < 2L) bad("a string is not closed")
      return(json_unescape(t, bad))
    }
    switch(t,
           "true" = TRUE, "false" = FALSE, "null" = NA,
           "NaN" = NaN, "Infinity" = Inf, "-Infinity" = -Inf,
           if (grepl("^-?[0-9]", t)) as.double(t) else bad(paste0("\"", t, "\" is no JSON value")))
  }
  if (!n) bad("it holds no value")
  v <- value()
  if (i < n) bad(paste0("text after its value (\"", tok[i + 1L], "\")"))
  v
}

# A string token's text: quotes removed, escapes replaced (\uXXXX
# surrogate pairs joined).
json_unescape <- function(t, bad) {
  s <- substr(t, 2L, nchar(t) - 1L)
  if (!grepl("\\", s, fixed = TRUE)) return(s)
  parts <- regmatches(s, gregexpr("\\\\u[0-9a-fA-F]{4}|\\\\.|[^\\\\]+", s, perl = TRUE))[[1]]
  if (!identical(paste(parts, collapse = ""), s)) bad("a string has a broken escape")
  codes <- integer(0)
  out <- character(length(parts))
  for (k in seq_along(parts)) {
    p <- parts[k]
    if (substr(p, 1L, 1L) != "\\") {
      out[k] <- p
      next
    }
    e <- substr(p, 2L, 2L)
    out[k] <- switch(e,
      "\"" = "\"", "\\" = "\\", "/" = "/", b = "\b", f = "\f", n = "\n", r = "\r", t = "\t",
      u = {
        code <- strtoi(substr(p, 3L, 6L), 16L)
        if (code >= 0xD800 && code <= 0xDBFF) {
          codes <- code
          ""
        } else if (code >= 0xDC00 && code <= 0xDFFF && length(codes)) {
          cp <- 0x10000 + (codes - 0xD800) * 0x400 + (code - 0xDC00)
          codes <- integer(0)
          intToUtf8(cp)
        } else {
          intToUtf8(code)
        }
      },
      bad(paste0("a string has the unknown escape \"", p, "\"")))
  }
  r <- paste(out, collapse = "")
  Encoding(r) <- "UTF-8"
  r
}

# The value of `key` in the parsed JSON `v`: the member of that name
# nearest the top (an object's own members before those of the values in
# it, which are searched in the file's order: a tool's results may sit in
# an object of their own); NULL when there is none.
json_find <- function(v, key) {
  if (!is.list(v)) return(NULL)
  nm <- names(v)
  if (!is.null(nm)) {
    hit <- which(nm == key)
    if (length(hit)) return(v[[hit[1]]])
  }
  for (el in v) {
    r <- json_find(el, key)
    if (!is.null(r)) return(r)
  }
  NULL
}
