// gzip (RFC 1952) compression of whole files in memory, with zlib. Logs may be stored as
// .csv.gz: the reader recognises the gzip magic bytes, the writer compresses when asked.
#pragma once

#include <string>

namespace bifilar {

// True when `bytes` begin with the gzip magic number (1f 8b).
bool LooksGzipped(const std::string& bytes);

// Deterministic gzip of `text` (no file name, modification time 0, level 9): the same text
// gives the same bytes.
std::string GzipCompress(const std::string& text);

// Inflates a whole gzip stream; false with *why set when the data are corrupt or truncated.
bool GzipDecompress(const std::string& bytes, std::string* text, std::string* why);

}  // namespace bifilar
