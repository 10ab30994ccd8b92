#include "mrpt_yesslam/sim/CBoxRaycaster.h"

#include "mrpt_yesslam/geometry/CPinholeCamera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>

namespace mrpt_yesslam
{
namespace
{
// A box as the inner loop needs it: the ray direction of pixel (c, r) in the box frame is
// a + c u + r v (linear in the pixel), the camera centre in the box frame is o.
struct TPrepared
{
	double a[3], u[3], v[3], o[3], h[3];
	int c0, c1, r0, r1;  // pixel bounds, inclusive
	double zNear;        // no pixel of this box is nearer than this (m)
	float shade[6];      // light factor per face: -x, +x, -y, +y, -z, +z
	const TRayBox* box;
};

// Face code: 2 * axis + (1 if the +h face, 0 if the -h face).
inline bool slab(const TPrepared& b, const double d[3], double zMax, double nearClip, double& t, int& face)
{
	double tmin = -std::numeric_limits<double>::infinity(), tmax = zMax;
	int f = -1;
	for (int k = 0; k < 3; k++)
	{
		if (d[k] == 0)
		{
			if (std::abs(b.o[k]) > b.h[k]) return false;
			continue;
		}
		const double inv = 1.0 / d[k];
		double t0 = (-b.h[k] - b.o[k]) * inv, t1 = (b.h[k] - b.o[k]) * inv;
		int enter = 2 * k;  // moving towards +: enters through the -h face
		if (t0 > t1)
		{
			std::swap(t0, t1);
			enter = 2 * k + 1;
		}
		if (t0 > tmin)
		{
			tmin = t0;
			f = enter;
		}
		tmax = std::min(tmax, t1);
		if (tmin > tmax) return false;
	}
	if (f < 0 || tmin <= nearClip) return false;
	t = tmin;
	face = f;
	return true;
}

// Texture coordinates of a hit point `p` (box frame) on `face`, oriented as the textured boxes
// that CSimWorld builds for MRPT (so scene.3Dscene shows the same texture layout).
inline void faceUv(int face, const double p[3], const double h[3], double& u, double& v)
{
	auto up = [&](int k) { return (p[k] + h[k]) / (2 * h[k]); };  // 0 at -h, 1 at +h
	auto down = [&](int k) { return (h[k] - p[k]) / (2 * h[k]); };
	switch (face)
	{
		case 0: u = down(1), v = down(2); break;  // -x
		case 1: u = up(1), v = down(2); break;    // +x
		case 2: u = up(0), v = down(2); break;    // -y
		case 3: u = down(0), v = down(2); break;  // +y
		case 4: u = up(1), v = down(0); break;    // -z
		default: u = up(0), v = down(1); break;   // +z
	}
}
}  // namespace

void CBoxRaycaster::render(const std::vector<TRayBox>& boxes, const mrpt::poses::CPose3D& Twc,
						   const mrpt::img::TCamera& K, cv::Mat& bgr, cv::Mat& depth, cv::Mat& instance,
						   cv::Range only) const
{
	const int W = static_cast<int>(K.ncols), H = static_cast<int>(K.nrows);
	if (only == cv::Range::all()) only = cv::Range(0, H);
	only = cv::Range(std::clamp(only.start, 0, H), std::clamp(only.end, 0, H));
	if (only.empty()) return;
	// The system's camera model (geometry/CPinholeCamera), so that the simulator and tracking
	// project with the same formula.
	const CPinholeCamera cam(K);
	const double fx = cam.fx(), fy = cam.fy(), cx = cam.cx(), cy = cam.cy();
	const mrpt::poses::CPose3D Tcw = -Twc;
	double L[3] = {options.lightDir[0], options.lightDir[1], options.lightDir[2]};
	const double ln = std::sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
	for (double& x : L) x /= ln > 0 ? ln : 1;

	std::vector<TPrepared> prep;
	prep.reserve(boxes.size());
	for (const auto& box : boxes)
	{
		TPrepared p;
		p.box = &box;
		p.h[0] = box.sx / 2;
		p.h[1] = box.sy / 2;
		p.h[2] = box.sz / 2;
		// Screen bounds from the projected corners; a box reaching behind the near plane may cover
		// any pixel, so it is tested everywhere.
		double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18, zmin = 1e18, zmax = -1e18;
		bool behind = false;
		for (int c = 0; c < 8; c++)
		{
			const mrpt::math::TPoint3D local((c & 1 ? 1 : -1) * p.h[0], (c & 2 ? 1 : -1) * p.h[1],
											 (c & 4 ? 1 : -1) * p.h[2]);
			const auto pc = Tcw.composePoint(box.pose.composePoint(local));
			zmin = std::min(zmin, pc.z);
			zmax = std::max(zmax, pc.z);
			if (pc.z <= options.nearClip)
			{
				behind = true;
				continue;
			}
			double uu = 0, vv = 0;
			cam.project(pc.x, pc.y, pc.z, uu, vv);
			umin = std::min(umin, uu);
			umax = std::max(umax, uu);
			vmin = std::min(vmin, vv);
			vmax = std::max(vmax, vv);
		}
		if (zmax <= options.nearClip) continue;  // wholly behind the camera
		if (behind)
		{
			p.c0 = 0, p.c1 = W - 1, p.r0 = 0, p.r1 = H - 1;
		}
		else
		{
			p.c0 = std::max(0, static_cast<int>(std::floor(umin)) - 1);
			p.c1 = std::min(W - 1, static_cast<int>(std::ceil(umax)) + 1);
			p.r0 = std::max(0, static_cast<int>(std::floor(vmin)) - 1);
			p.r1 = std::min(H - 1, static_cast<int>(std::ceil(vmax)) + 1);
			if (p.c0 > p.c1 || p.r0 > p.r1) continue;  // outside the image
		}
		p.zNear = std::max(options.nearClip, zmin);
		// Camera in the box frame: direction of pixel (c, r) is R [(c - cx)/fx, (r - cy)/fy, 1].
		const mrpt::poses::CPose3D Tbc = (-box.pose) + Twc;
		const auto R = Tbc.getRotationMatrix();
		for (int i = 0; i < 3; i++)
		{
			p.u[i] = R(i, 0) / fx;
			p.v[i] = R(i, 1) / fy;
			p.a[i] = R(i, 2) - cx * p.u[i] - cy * p.v[i];
		}
		p.o[0] = Tbc.x();
		p.o[1] = Tbc.y();
		p.o[2] = Tbc.z();
		// Lambertian factor per face from its world normal, as MRPT's shader: ambient + diffuse max(n.-L, 0).
		const auto Rw = box.pose.getRotationMatrix();
		for (int f = 0; f < 6; f++)
		{
			const int k = f / 2;
			const double s = (f % 2) ? 1.0 : -1.0;
			const double nl = -(s * Rw(0, k) * L[0] + s * Rw(1, k) * L[1] + s * Rw(2, k) * L[2]);
			p.shade[f] = options.ambient + options.diffuse * static_cast<float>(std::max(0.0, nl));
		}
		prep.push_back(p);
	}
	// Front to back: a pixel already covered by something nearer than a box's nearest corner
	// skips that box's slab test.
	std::stable_sort(prep.begin(), prep.end(),
					 [](const TPrepared& x, const TPrepared& y) { return x.zNear < y.zNear; });

	bgr.create(H, W, CV_8UC3);
	depth.create(H, W, CV_32F);
	instance.create(H, W, CV_16U);
	const double nearClip = options.nearClip;
	// Rows are independent: stripes in parallel give the same images as one thread.
	cv::parallel_for_(
		only,
		[&](const cv::Range& rows)
		{
			const int n = (rows.end - rows.start) * W;
			std::vector<double> z(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
			std::vector<int> who(static_cast<std::size_t>(n), -1);
			std::vector<uint8_t> face(static_cast<std::size_t>(n), 0);
			for (std::size_t bi = 0; bi < prep.size(); bi++)
			{
				const TPrepared& b = prep[bi];
				const int r0 = std::max(b.r0, rows.start), r1 = std::min(b.r1, rows.end - 1);
				for (int r = r0; r <= r1; r++)
				{
					double d[3] = {b.a[0] + r * b.v[0] + b.c0 * b.u[0], b.a[1] + r * b.v[1] + b.c0 * b.u[1],
								   b.a[2] + r * b.v[2] + b.c0 * b.u[2]};
					const std::size_t row = static_cast<std::size_t>(r - rows.start) * static_cast<std::size_t>(W);
					for (int c = b.c0; c <= b.c1; c++, d[0] += b.u[0], d[1] += b.u[1], d[2] += b.u[2])
					{
						const std::size_t i = row + static_cast<std::size_t>(c);
						if (z[i] <= b.zNear) continue;
						double t;
						int f;
						if (slab(b, d, z[i], nearClip, t, f))
						{
							z[i] = t;
							who[i] = static_cast<int>(bi);
							face[i] = static_cast<uint8_t>(f);
						}
					}
				}
			}
			for (int r = rows.start; r < rows.end; r++)
			{
				auto* pc = bgr.ptr<cv::Vec3b>(r);
				auto* pz = depth.ptr<float>(r);
				auto* pi = instance.ptr<uint16_t>(r);
				const std::size_t row = static_cast<std::size_t>(r - rows.start) * static_cast<std::size_t>(W);
				for (int c = 0; c < W; c++)
				{
					const std::size_t i = row + static_cast<std::size_t>(c);
					if (who[i] < 0)
					{
						pc[c] = cv::Vec3b(0, 0, 0);
						pz[c] = 0;
						pi[c] = 0;
						continue;
					}
					const TPrepared& b = prep[static_cast<std::size_t>(who[i])];
					pz[c] = static_cast<float>(z[i]);
					pi[c] = b.box->id;
					const double t = z[i];
					double p[3];
					for (int k = 0; k < 3; k++) p[k] = b.o[k] + t * (b.a[k] + c * b.u[k] + r * b.v[k]);
					const float s = b.shade[face[i]];
					if (!b.box->texture || b.box->texture->empty())
					{
						const uint8_t g = cv::saturate_cast<uint8_t>(128 * s);
						pc[c] = cv::Vec3b(g, g, g);
						continue;
					}
					double u, v;
					faceUv(face[i], p, b.h, u, v);
					const cv::Mat& tex = *b.box->texture;
					const int tx = std::clamp(static_cast<int>(u * tex.cols), 0, tex.cols - 1);
					const int ty = std::clamp(static_cast<int>(v * tex.rows), 0, tex.rows - 1);
					const cv::Vec3b tc = tex.at<cv::Vec3b>(ty, tx);
					pc[c] = cv::Vec3b(cv::saturate_cast<uint8_t>(tc[0] * s), cv::saturate_cast<uint8_t>(tc[1] * s),
									  cv::saturate_cast<uint8_t>(tc[2] * s));
				}
			}
		});
}
}  // namespace mrpt_yesslam
