#pragma once
// libdeflate with one (de)compressor per thread: the PNG decoder inflates dataset images on the
// reader thread, the dense mapper packs keyframe clouds on its stage and unpacks them while it builds.
// Private to the library (libdeflate is not part of its public interface).
#include <cstddef>
#include <cstdint>
#include <vector>

struct libdeflate_decompressor;

namespace mrpt_yesslam
{
/** This thread's libdeflate decompressor (made on first use, freed with the thread; null when out of memory). */
libdeflate_decompressor* threadDecompressor();

/** `n` bytes as a raw DEFLATE stream at `level` (1 fastest .. 12 smallest), in a buffer of its own size. */
std::vector<std::uint8_t> deflateBytes(const void* data, std::size_t n, int level);

/** A raw DEFLATE stream (deflateBytes's) inflated into exactly `n` bytes at `out`; false if it does not
 * hold exactly that many, is corrupt, or no decompressor could be made. */
bool inflateBytes(const std::vector<std::uint8_t>& packed, void* out, std::size_t n);
}  // namespace mrpt_yesslam
