#include "mrpt_yesslam/dense/CObjectSegmenter.h"

#include <algorithm>
#include <cmath>

namespace mrpt_yesslam
{
namespace
{
// Scratch images, one set per thread: fresh megabyte-sized buffers on every keyframe cost more in
// page faults than the segmentation itself.
struct TScratch
{
	std::vector<cv::Vec3f> P, N;
	std::vector<float> z0, tmp, out;
	std::vector<int> seg;
	std::vector<cv::Point> queue;
};

// Per segment: size, how much of it lies in the margin around the box, and its outline: where it
// is in front of what is beside it (occluding) or behind it (occluded).
struct TSegment
{
	int pixels = 0, inMargin = 0, occluding = 0, occluded = 0;
};

}  // namespace

TObjectLabels CObjectSegmenter::segment(const cv::Mat& depth, const mrpt::img::TCamera& camera,
										const std::vector<TDetection>& dets) const
{
	TObjectLabels r;
	r.instance = cv::Mat::zeros(depth.size(), CV_16U);
	r.unknown = cv::Mat::zeros(depth.size(), CV_8U);
	if (dets.empty() || depth.empty() || depth.type() != CV_32F) return r;
	const int f = std::max(1, p_.downsample);
	const int W = depth.cols / f, H = depth.rows / f;
	if (W < 5 || H < 5) return r;
	const cv::Rect image(0, 0, W, H);
	const float fx = static_cast<float>(camera.fx()), fy = static_cast<float>(camera.fy());
	const float cx = static_cast<float>(camera.cx()), cy = static_cast<float>(camera.cy());

	// Points at the working resolution: nearest samples, so no depth is mixed across an edge.
	thread_local TScratch scratch;
	std::vector<cv::Vec3f>& P = scratch.P;
	std::vector<cv::Vec3f>& N = scratch.N;
	P.resize(static_cast<std::size_t>(W * H));
	N.assign(P.size(), cv::Vec3f(0, 0, 0));  // 0 = no normal
	auto at = [&](int x, int y) { return static_cast<std::size_t>(y * W + x); };
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++)
		{
			const float z = depth.at<float>(y * f, x * f);
			P[at(x, y)] = z > 0 && std::isfinite(z) ? cv::Vec3f((x * f - cx) * z / fx, (y * f - cy) * z / fy, z)
													: cv::Vec3f(0, 0, 0);
		}
	// Depth is smoothed first, within surfaces only (neighbours within 4 % of the pixel's depth, a
	// separable edge-preserving mean over 7 x 7 samples): structured-light depth is quantised in
	// steps of about 3e-3 z^2 (3 cm at 3 m), so normals of raw neighbours would be noise.
	{
		const int r = 3;
		std::vector<float>&tmp = scratch.tmp, &out = scratch.out, &z0 = scratch.z0;
		tmp.assign(P.size(), 0.f);
		out.assign(P.size(), 0.f);
		auto pass = [&](const std::vector<float>& in, std::vector<float>& res, int ddx, int ddy)
		{
			for (int y = 0; y < H; y++)
				for (int x = 0; x < W; x++)
				{
					const float z = in[at(x, y)];
					if (z <= 0) continue;
					float sum = 0;
					int n = 0;
					for (int k = -r; k <= r; k++)
					{
						const int u = x + k * ddx, v = y + k * ddy;
						if (u < 0 || v < 0 || u >= W || v >= H) continue;
						const float zn = in[at(u, v)];
						if (zn > 0 && std::abs(zn - z) < 0.04f * z) sum += zn, n++;
					}
					res[at(x, y)] = sum / static_cast<float>(n);
				}
		};
		z0.resize(P.size());
		for (std::size_t i = 0; i < P.size(); i++) z0[i] = P[i][2];
		pass(z0, tmp, 1, 0);
		pass(tmp, out, 0, 1);
		for (int y = 0; y < H; y++)
			for (int x = 0; x < W; x++)
			{
				const float z = out[at(x, y)];
				if (z > 0) P[at(x, y)] = cv::Vec3f((x * f - cx) * z / fx, (y * f - cy) * z / fy, z);
			}
	}
	// Normals from central differences two samples apart; none across a depth edge, where they
	// would mix two surfaces.
	const int s = 2;
	for (int y = s; y < H - s; y++)
		for (int x = s; x < W - s; x++)
		{
			const cv::Vec3f &a = P[at(x + s, y)], &b = P[at(x - s, y)], &c = P[at(x, y + s)], &d = P[at(x, y - s)],
							&p = P[at(x, y)];
			if (p[2] <= 0 || a[2] <= 0 || b[2] <= 0 || c[2] <= 0 || d[2] <= 0) continue;
			const float edge = 0.25f * p[2];
			if (std::abs(a[2] - b[2]) > edge || std::abs(c[2] - d[2]) > edge) continue;
			cv::Vec3f n = (a - b).cross(c - d);
			const float len = static_cast<float>(cv::norm(n));
			if (!(len > 0)) continue;
			n /= len;
			if (n.dot(p) > 0) n = -n;  // towards the camera
			N[at(x, y)] = n;
		}

	const float cosMax = static_cast<float>(std::cos(p_.maxNormalAngleDeg * M_PI / 180.0));
	// Same surface: normals agree and each point lies near the other's tangent plane (the
	// tolerance grows with depth squared, as structured-light depth noise does).
	auto joins = [&](std::size_t i, std::size_t j)
	{
		const cv::Vec3f &ni = N[i], &nj = N[j];
		if (ni[2] == 0 && ni[0] == 0 && ni[1] == 0) return false;
		if (nj[2] == 0 && nj[0] == 0 && nj[1] == 0) return false;
		if (ni.dot(nj) < cosMax) return false;
		const cv::Vec3f d = P[j] - P[i];
		const float z = P[i][2];
		const float tol = std::max(0.004f, static_cast<float>(p_.planeDistance) * z * z);
		return std::abs(ni.dot(d)) < tol && std::abs(nj.dot(d)) < tol;
	};
	static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};

	std::vector<int>& seg = scratch.seg;
	std::vector<cv::Point>& queue = scratch.queue;
	for (std::size_t di = 0; di < dets.size(); di++)
	{
		const cv::Rect2f& b = dets[di].box;
		const cv::Rect R = coveringRect(b, p_.margin, f, image);
		const cv::Rect inner = coveringRect(b, 0, f, image);
		if (R.area() <= 0 || inner.area() <= 0) continue;
		seg.assign(static_cast<std::size_t>(R.area()), -1);
		auto sat = [&](int x, int y) -> int& { return seg[static_cast<std::size_t>((y - R.y) * R.width + (x - R.x))]; };
		std::vector<TSegment> segs;
		// 1. Smooth-surface segments inside the grown box.
		for (int y = R.y; y < R.br().y; y++)
			for (int x = R.x; x < R.br().x; x++)
			{
				if (sat(x, y) >= 0 || P[at(x, y)][2] <= 0) continue;
				const cv::Vec3f& n = N[at(x, y)];
				if (n[0] == 0 && n[1] == 0 && n[2] == 0) continue;
				const int id = static_cast<int>(segs.size());
				segs.emplace_back();
				sat(x, y) = id;
				// Grown breadth first against the segment's mean normal as well as the neighbour's:
				// smoothing rounds corners, and a neighbour-only test would creep round them.
				cv::Vec3f sum = n;
				queue.assign(1, cv::Point(x, y));
				for (std::size_t head = 0; head < queue.size(); head++)
				{
					const cv::Point q = queue[head];
					const cv::Vec3f mean = sum / static_cast<float>(cv::norm(sum));
					for (int k = 0; k < 4; k++)
					{
						const int u = q.x + dx[k], v = q.y + dy[k];
						if (u < R.x || v < R.y || u >= R.br().x || v >= R.br().y || sat(u, v) >= 0) continue;
						if (!joins(at(q.x, q.y), at(u, v)) || N[at(u, v)].dot(mean) < cosMax) continue;
						sat(u, v) = id;
						sum += N[at(u, v)];
						queue.emplace_back(u, v);
					}
				}
			}
		// Pixels without a normal (silhouettes, thin parts) join a neighbouring segment of nearly
		// the same depth, two layers deep.
		for (int pass = 0; pass < 2; pass++)
		{
			std::vector<std::pair<cv::Point, int>> add;
			for (int y = R.y; y < R.br().y; y++)
				for (int x = R.x; x < R.br().x; x++)
				{
					const float z = P[at(x, y)][2];
					if (sat(x, y) >= 0 || z <= 0) continue;
					for (int k = 0; k < 4; k++)
					{
						const int u = x + dx[k], v = y + dy[k];
						if (u < R.x || v < R.y || u >= R.br().x || v >= R.br().y || sat(u, v) < 0) continue;
						if (std::abs(P[at(u, v)][2] - z) < 0.03f * z)
						{
							add.emplace_back(cv::Point(x, y), sat(u, v));
							break;
						}
					}
				}
			for (const auto& [p, id] : add) sat(p.x, p.y) = id;
		}
		// 2. What each segment is: inside the box or running on beyond it, in front or behind.
		for (int y = R.y; y < R.br().y; y++)
			for (int x = R.x; x < R.br().x; x++)
			{
				const int id = sat(x, y);
				if (id < 0) continue;
				TSegment& sg = segs[static_cast<std::size_t>(id)];
				sg.pixels++;
				sg.inMargin += !inner.contains(cv::Point(x, y));
				const float z = P[at(x, y)][2];
				for (int k = 0; k < 4; k++)
				{
					const int u = x + dx[k], v = y + dy[k];
					if (!image.contains(cv::Point(u, v))) continue;
					const bool inR = R.contains(cv::Point(u, v));
					if (inR && sat(u, v) == id) continue;
					const float zn = P[at(u, v)][2];
					if (zn <= 0) continue;
					if (zn > z * 1.05f + 0.02f)
						sg.occluding++;
					else if (zn < z * 0.95f - 0.02f)
						sg.occluded++;
				}
			}
		const int minPixels = std::max(4, static_cast<int>(p_.minBoxShare * inner.area()));
		std::vector<bool> object(segs.size(), false);
		bool any = false;
		for (std::size_t k = 0; k < segs.size(); k++)
		{
			const TSegment& sg = segs[k];
			const bool inside = sg.pixels >= minPixels && sg.inMargin <= p_.maxMarginShare * sg.pixels;
			// Seen through a gap of the object: behind its neighbours along most of its outline.
			const bool throughGap = sg.occluded > 3 * sg.occluding + 2;
			object[k] = inside && !throughGap;
			any |= object[k];
		}
		if (!any)
		{
			// Nothing found: no evidence either way (not "background") where no other box spoke.
			const cv::Rect full = cv::Rect(inner.x * f, inner.y * f, inner.width * f, inner.height * f) &
								  cv::Rect(0, 0, depth.cols, depth.rows);
			r.unknown(full).setTo(255);
			continue;
		}
		const std::uint16_t lab = static_cast<std::uint16_t>(std::min<std::size_t>(di + 1, 65535));
		for (int y = R.y; y < R.br().y; y++)
			for (int x = R.x; x < R.br().x; x++)
			{
				const int id = sat(x, y);
				if (id < 0 || !object[static_cast<std::size_t>(id)]) continue;
				for (int v = y * f; v < std::min(depth.rows, (y + 1) * f); v++)
				{
					std::uint16_t* row = r.instance.ptr<std::uint16_t>(v);
					for (int u = x * f; u < std::min(depth.cols, (x + 1) * f); u++) row[u] = lab;
				}
			}
	}
	r.unknown.setTo(0, r.instance != 0);
	return r;
}
}  // namespace mrpt_yesslam
