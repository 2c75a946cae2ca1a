#pragma once
// Writes a camera frame losslessly as a 16-bit PNG or TIFF, atomically
// (temporary file, fsync, rename). Levels of formats with fewer than 16 bits
// are widened by bit replication (v16 = v << (16 - n) | v >> (2n - 16), e.g. v
// * 257 for 8 bits): full scale becomes 65535, and the original level is v16 >>
// (16 - n) exactly. Bayer mosaics are stored undemosaiced as one channel; RGB8
// as three.

#include <filesystem>
#include <string>

#include "capture/camera.h"

namespace igi::capture {

// The 16-bit value stored for `level` of an `significant_bits`-bit format.
uint16_t WidenTo16Bits(uint16_t level, int significant_bits);

// Writes `frame` to `path` (format from the extension: .png or .tif/.tiff). PNG
// uses fast zlib compression, TIFF none. Always through a temporary file
// renamed into place; `durable` also fsyncs it first (survives a power cut, not
// only a crash; costs a disk flush per frame). Throws igi::Error if the file
// cannot be written.
void WriteFrame(const std::filesystem::path& path, const Frame& frame, bool durable = true);

}  // namespace igi::capture
