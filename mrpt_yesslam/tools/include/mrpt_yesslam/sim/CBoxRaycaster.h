#pragma once
// yesslam-sim's renderer: casts one ray per pixel through a world made only of textured, oriented
// boxes and gives colour, exact metric depth and the instance id of what each pixel sees in a
// single pass.
//
// Why not MRPT's CFBORender (used first): here it runs on Mesa's llvmpipe, slowly and in two passes, its depth is a
// sawtooth around the truth that needed a ray cast anyway, and it samples pixel k at k + 0.5. A ray cast against the
// boxes' slabs is exact, samples pixel centres like TUM and costs a fraction of one pass (bench/bench_sim.sh).
// The images are what a one-sample-per-pixel rasteriser produces (no anti-aliasing): nearest
// texel, Lambertian light as MRPT's textured-triangle shader, so scene.3Dscene looks the same.
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace mrpt_yesslam
{
/** A box to render: world pose of its centre, full extents, texture and instance id. */
struct TRayBox
{
	mrpt::poses::CPose3D pose;
	double sx = 0.1, sy = 0.1, sz = 0.1;
	const cv::Mat* texture = nullptr;  //!< BGR 8UC3, stretched over each face; null = grey
	uint16_t id = 0;                   //!< written to the instance image (0 = nothing)
};

/** Renders box worlds by ray casting (colour, depth and instance ids in one pass). */
class CBoxRaycaster
{
   public:
	/** Lighting, as MRPT's default viewport light but brighter ambient (an indoor room). */
	struct TOptions
	{
		float ambient = 0.55f, diffuse = 0.6f;
		/** Direction the light travels, world frame (normalised on use). */
		float lightDir[3] = {-0.40825f, -0.40825f, -0.81650f};
		/** Nothing nearer than this (m) is seen, as a camera's near clip. */
		double nearClip = 0.05;
	};

	CBoxRaycaster() = default;
	explicit CBoxRaycaster(const TOptions& o) : options(o) {}

	/** Renders `boxes` from camera pose `Twc` (optical frame: z forward, x right, y down) with
	 * pinhole `K` (pixel centres at integer coordinates). Outputs: `bgr` 8UC3, `depth` 32F in
	 * metres along z (0 = nothing), `instance` 16U (box id, 0 = nothing). With `rows`, only those
	 * rows are written (the others keep what the images held): a rolling shutter renders each band
	 * of rows from the camera's pose at its own moment. */
	void render(const std::vector<TRayBox>& boxes, const mrpt::poses::CPose3D& Twc, const mrpt::img::TCamera& K,
				cv::Mat& bgr, cv::Mat& depth, cv::Mat& instance, cv::Range rows = cv::Range::all()) const;

	TOptions options;
};
}  // namespace mrpt_yesslam
