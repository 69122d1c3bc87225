// gzip (RFC 1952) compression of whole files in memory, with zlib. Logs may be stored as
// .csv.gz: the reader recognises the gzip magic bytes, the writer compresses when asked.
#pragma once

#include <string>

#include "base/bounded_read.h"

namespace bifilar {

// True when `bytes` begin with the gzip magic number (1f 8b).
bool LooksGzipped(const std::string& bytes);

// Deterministic gzip of `text` (no file name, modification time 0, level 9): the same text
// gives the same bytes.
std::string GzipCompress(const std::string& text);

// Inflates a whole gzip file: every member of it, as zcat does (`cat a.gz b.gz > log.csv.gz` is
// one file whose text is a's then b's); zero bytes after the last member (padding) are ignored.
// False with *why set when the data are corrupt or truncated, when other bytes follow a member,
// or when the text would exceed cap.max_bytes (a gzip bomb: inflation stops at the cap, so the
// memory used is bounded by it).
bool GzipDecompress(const std::string& bytes, std::string* text, std::string* why,
                    const InputCap& cap);

}  // namespace bifilar
