#include "base/gzip.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <zlib.h>

namespace bifilar {

bool LooksGzipped(const std::string& bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

std::string GzipCompress(const std::string& text) {
  z_stream stream;
  std::memset(&stream, 0, sizeof(stream));
  // windowBits 15 + 16: a gzip wrapper with a zero header (no name, mtime 0).
  if (deflateInit2(&stream, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw std::runtime_error("zlib: deflateInit2 failed");
  }
  std::string out(deflateBound(&stream, text.size()), '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  stream.avail_in = static_cast<uInt>(text.size());
  stream.next_out = reinterpret_cast<Bytef*>(&out[0]);
  stream.avail_out = static_cast<uInt>(out.size());
  const int status = deflate(&stream, Z_FINISH);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  if (status != Z_STREAM_END) throw std::runtime_error("zlib: deflate did not finish");
  return out;
}

bool GzipDecompress(const std::string& bytes, std::string* text, std::string* why,
                    const InputCap& cap) {
  text->clear();
  z_stream stream;
  std::memset(&stream, 0, sizeof(stream));
  if (inflateInit2(&stream, 15 + 16) != Z_OK) {
    *why = "zlib: inflateInit2 failed";
    return false;
  }
  auto fail = [&](const std::string& message) {
    inflateEnd(&stream);
    text->clear();
    text->shrink_to_fit();
    *why = message;
    return false;
  };
  // zlib counts input in uInt (32 bits): a large file is handed over in pieces.
  const auto* data = reinterpret_cast<const Bytef*>(bytes.data());
  size_t handed = 0;  // bytes given to zlib so far; consumed = handed - stream.avail_in
  int member = 1;
  char buffer[1 << 16];
  for (;;) {
    if (stream.avail_in == 0 && handed < bytes.size()) {
      const size_t n = std::min<size_t>(bytes.size() - handed, size_t{1} << 30);
      stream.next_in = const_cast<Bytef*>(data + handed);
      stream.avail_in = static_cast<uInt>(n);
      handed += n;
    }
    stream.next_out = reinterpret_cast<Bytef*>(buffer);
    stream.avail_out = sizeof(buffer);
    const int status = inflate(&stream, Z_NO_FLUSH);
    const size_t produced = sizeof(buffer) - stream.avail_out;
    if (produced > cap.max_bytes - text->size()) {  // a gzip bomb stops here, at the cap
      return fail(CapExceeded(cap, 0, false));
    }
    text->append(buffer, produced);
    if (status == Z_OK) continue;
    if (status == Z_BUF_ERROR && (stream.avail_in > 0 || handed < bytes.size())) continue;
    if (status == Z_BUF_ERROR) {
      return fail("not a valid gzip file (truncated" +
                  (member > 1 ? " in member " + std::to_string(member) : std::string()) + ")");
    }
    if (status != Z_STREAM_END) {
      return fail(std::string("not a valid gzip file (") +
                  (stream.msg ? stream.msg : "corrupt data") +
                  (member > 1 ? " in member " + std::to_string(member) : std::string()) + ")");
    }
    // The end of one member: another member, zero padding, or the end of the file.
    const size_t consumed = handed - stream.avail_in;
    if (consumed == bytes.size()) break;
    if (LooksGzipped(bytes.substr(consumed, 2))) {
      inflateReset(&stream);  // keeps next_in/avail_in: the next member is read from there
      ++member;
      continue;
    }
    if (bytes.find_first_not_of('\0', consumed) == std::string::npos) break;
    return fail("not a valid gzip file (" + std::to_string(bytes.size() - consumed) +
                " bytes after the end of gzip member " + std::to_string(member) + " at byte " +
                std::to_string(consumed) + " are not another gzip member)");
  }
  inflateEnd(&stream);
  return true;
}

}  // namespace bifilar
