#pragma once
// What the dense mapper's two files share (private to the library): a keyframe cloud as stored,
// packed, and the voxel key and transform both the insertion and the final build use.
#include <opencv2/core.hpp>
#include <mrpt/poses/CPose3D.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "mrpt_yesslam/dense/CDenseSemanticMapper.h"
#include "../util/Deflate.h"

namespace mrpt_yesslam
{
namespace dense_detail
{
// A voxel key: three 21-bit signed cell indices (+-10 km at 1 cm).
inline std::int64_t voxelKey(const cv::Point3f& p, double inv)
{
	auto c = [&](float v) { return (static_cast<std::int64_t>(std::floor(v * inv)) + (1 << 20)) & 0x1FFFFF; };
	return (c(p.x) << 42) | (c(p.y) << 21) | c(p.z);
}

inline cv::Point3f transform(const mrpt::poses::CPose3D& T, const cv::Point3f& p)
{
	double x, y, z;
	T.composePoint(p.x, p.y, p.z, x, y, z);
	return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}
}  // namespace dense_detail

struct CDenseSemanticMapper::TPackedCloud
{
	struct TPoint
	{
		std::int16_t x, y, z;  //!< keyframe frame, in steps of the mapper's unit_
		std::uint8_t b, g, r;
		TSemLabel label;
		std::uint8_t prob;  //!< labelProb x 255 (0 = no label evidence)
	};
	static_assert(sizeof(TPoint) == 12, "12 bytes a point unpacked");
	static constexpr std::size_t kPlanes =
		11;  //!< bytes a point, planar: x, y, z deltas (low, high), b, g, r, label, prob

	std::size_t size = 0;  //!< points
	/** The points DEFLATEd as planes of bytes, each coordinate as its difference from the point
	 * before (issue 41 item 5: a long run keeps one cloud per keyframe, culled ones included; the
	 * points come in pixel order, so neighbours differ little and a plane's bytes repeat).
	 * About 5 bytes a point instead of 12, exactly the same points back. */
	std::vector<std::uint8_t> bytes;

	static std::shared_ptr<const TPackedCloud> pack(const std::vector<TPoint>& pts)
	{
		const std::size_t n = pts.size();
		std::vector<std::uint8_t> planes(n * kPlanes);
		std::int16_t prev[3] = {0, 0, 0};
		for (std::size_t i = 0; i < n; i++)
		{
			const TPoint& p = pts[i];
			const std::int16_t v[3] = {p.x, p.y, p.z};
			for (int a = 0; a < 3; a++)
			{
				const auto d =
					static_cast<std::uint16_t>(static_cast<std::uint16_t>(v[a]) - static_cast<std::uint16_t>(prev[a]));
				planes[(2 * a) * n + i] = static_cast<std::uint8_t>(d & 0xFF);
				planes[(2 * a + 1) * n + i] = static_cast<std::uint8_t>(d >> 8);
				prev[a] = v[a];
			}
			planes[6 * n + i] = p.b, planes[7 * n + i] = p.g, planes[8 * n + i] = p.r;
			planes[9 * n + i] = p.label, planes[10 * n + i] = p.prob;
		}
		auto c = std::make_shared<TPackedCloud>();
		c->size = n;
		// Level 1: nearly all the packing at little cost in time; higher levels take much longer to save little more
		// (docs/benchmarks.md, "The memory work of 2026-11-28, third round: the dense store packed, the network let
		// go").
		c->bytes = deflateBytes(planes.data(), planes.size(), 1);
		return c;
	}

	/** The points, as packed, into `out` (reused between calls to keep its allocation). */
	void unpack(std::vector<TPoint>& out, std::vector<std::uint8_t>& planes) const
	{
		const std::size_t n = size;
		planes.resize(n * kPlanes);
		// Only this mapper's own packing is ever read (nothing loads it from a file): failing here
		// means memory was corrupted or no decompressor could be had.
		if (!inflateBytes(bytes, planes.data(), planes.size()))
			throw std::runtime_error("dense map: a stored keyframe cloud could not be unpacked (out of memory?)");
		out.resize(n);
		std::uint16_t acc[3] = {0, 0, 0};
		for (std::size_t i = 0; i < n; i++)
		{
			TPoint& p = out[i];
			for (int a = 0; a < 3; a++)
				acc[a] =
					static_cast<std::uint16_t>(acc[a] + (planes[(2 * a) * n + i] | (planes[(2 * a + 1) * n + i] << 8)));
			// (uint16 -> int16 above 32767 wraps, as the packing's uint16 differences assume: GCC and Clang define it
			// so.)
			p.x = static_cast<std::int16_t>(acc[0]), p.y = static_cast<std::int16_t>(acc[1]),
			p.z = static_cast<std::int16_t>(acc[2]);
			p.b = planes[6 * n + i], p.g = planes[7 * n + i], p.r = planes[8 * n + i];
			p.label = planes[9 * n + i], p.prob = planes[10 * n + i];
		}
	}
};
}  // namespace mrpt_yesslam
