#include "Deflate.h"

#include <libdeflate.h>

#include <memory>
#include <new>
#include <stdexcept>

namespace mrpt_yesslam
{
libdeflate_decompressor* threadDecompressor()
{
	struct Free
	{
		void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
	};
	thread_local std::unique_ptr<libdeflate_decompressor, Free> d;
	if (!d) d.reset(libdeflate_alloc_decompressor());  // again after a failed allocation
	return d.get();
}

std::vector<std::uint8_t> deflateBytes(const void* data, std::size_t n, int level)
{
	struct Free
	{
		void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
	};
	// A compressor holds its level's tables (hundreds of KB): one per thread and level in use.
	thread_local int madeFor = -1;
	thread_local std::unique_ptr<libdeflate_compressor, Free> c;
	if (madeFor != level || !c)
	{
		c.reset(libdeflate_alloc_compressor(level));
		if (!c) throw std::bad_alloc();
		madeFor = level;
	}
	std::vector<std::uint8_t> out(libdeflate_deflate_compress_bound(c.get(), n));
	const std::size_t size = libdeflate_deflate_compress(c.get(), n ? data : out.data(), n, out.data(), out.size());
	// Never 0 for a buffer of the bound's size (libdeflate's contract): an empty stream would only
	// be found out when it is inflated.
	if (size == 0) throw std::logic_error("libdeflate: compression into a buffer of its bound's size failed");
	out.resize(size);
	out.shrink_to_fit();
	return out;
}

bool inflateBytes(const std::vector<std::uint8_t>& packed, void* out, std::size_t n)
{
	libdeflate_decompressor* d = threadDecompressor();
	if (!d) return false;
	std::size_t got = 0;
	return libdeflate_deflate_decompress(d, packed.data(), packed.size(), out, n, &got) == LIBDEFLATE_SUCCESS &&
		   got == n;
}
}  // namespace mrpt_yesslam
