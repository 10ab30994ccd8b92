#include "mrpt_yesslam/render/SceneRenderer.h"

#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/COpenGLViewport.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfObjects.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <opencv2/imgcodecs.hpp>

#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
// The extent of everything in the main viewport, in world coordinates. COpenGLScene::
// getBoundingBox() misses point clouds before their first render (their box is built lazily), and
// in MRPT 2.5 a CSetOfObjects' box leaves out its children's poses (yesslam-sim's objects are boxes
// placed inside sets: the room came out centred on the origin), so sets are walked here with their
// poses composed; a leaf's own box already includes its pose.
bool sceneBounds(const mrpt::opengl::COpenGLScene& scene, mrpt::math::TPoint3D& lo, mrpt::math::TPoint3D& hi)
{
	bool any = false;
	auto grow = [&](const mrpt::math::TPoint3D& p)
	{
		if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return;
		if (!any) lo = hi = p;
		lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
		hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
		any = true;
	};
	std::function<void(const mrpt::opengl::CRenderizable&, const mrpt::poses::CPose3D&)> add =
		[&](const mrpt::opengl::CRenderizable& o, const mrpt::poses::CPose3D& parent)
	{
		const mrpt::poses::CPose3D pose = parent + mrpt::poses::CPose3D(o.getPose());
		auto addCloud = [&](const auto& pc)
		{
			for (std::size_t i = 0; i < pc.size(); i++)
			{
				const auto& p = pc.getPoint3Df(i);
				grow(pose.composePoint(mrpt::math::TPoint3D(p.x, p.y, p.z)));
			}
		};
		if (const auto* set = dynamic_cast<const mrpt::opengl::CSetOfObjects*>(&o))
		{
			for (const auto& child : *set)
				if (child) add(*child, pose);
			return;
		}
		if (const auto* pc = dynamic_cast<const mrpt::opengl::CPointCloudColoured*>(&o)) return addCloud(*pc);
		if (const auto* pc = dynamic_cast<const mrpt::opengl::CPointCloud*>(&o)) return addCloud(*pc);
		try
		{
			const auto bb = o.getBoundingBox();
			// A leaf's box is in its parent's frame already (its own pose applied).
			for (int c = 0; c < 8; c++)
				grow(parent.composePoint(mrpt::math::TPoint3D(
					(c & 1) ? bb.max.x : bb.min.x, (c & 2) ? bb.max.y : bb.min.y, (c & 4) ? bb.max.z : bb.min.z)));
		}
		catch (const std::exception&)
		{
			// Objects without extent (empty sets) do not count.
		}
	};
	const auto vp = scene.getViewport("main");
	if (!vp) return false;
	for (const auto& o : *vp)
		if (o) add(*o, mrpt::poses::CPose3D());
	return any;
}
}  // namespace

void loadScene(const std::string& path, mrpt::opengl::COpenGLScene& scene)
{
	std::error_code ec;
	if (!std::filesystem::exists(path, ec)) throw InputError(path, "file not found");
	if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a folder, expected a .3Dscene file");
	bool ok = false;
	try
	{
		ok = scene.loadFromFile(path);
	}
	catch (const std::exception& e)
	{
		throw InputError(path, "not a readable .3Dscene file (" + exceptionSummary(e.what()) + ")");
	}
	if (!ok) throw InputError(path, "not a readable .3Dscene file");
}

mrpt::img::CImage renderScene(mrpt::opengl::COpenGLScene& scene, const TRenderOptions& o)
{
	if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192)
		throw InputError("", "image size must be between 16 and 8192 pixels");
	auto vp = scene.getViewport("main");
	if (!vp) throw InputError("", "scene has no 'main' viewport");
	if (!o.hide.empty())
	{
		std::vector<mrpt::opengl::CRenderizable::Ptr> drop;
		for (const auto& obj : *vp)
			if (obj && std::any_of(o.hide.begin(), o.hide.end(), [&](const std::string& h) { return !h.empty() && obj->getName().rfind(h, 0) == 0; }))
				drop.push_back(obj);
		for (const auto& obj : drop) vp->removeObject(obj);
	}
	vp->setCustomBackgroundColor(mrpt::img::TColorf(
		static_cast<float>(o.background[0]), static_cast<float>(o.background[1]), static_cast<float>(o.background[2])));

	// Default view: look at the centre of the scene from far enough to see all of it.
	mrpt::math::TPoint3D centre(0, 0, 0);
	double radius = 1.0;
	mrpt::math::TPoint3D lo, hi;
	if (sceneBounds(scene, lo, hi))
	{
		const auto d = hi - lo;
		if (d.norm() > 0 && d.norm() < 1e6)
		{
			centre = (lo + hi) * 0.5;
			radius = 0.5 * d.norm();
		}
	}
	const double fov = std::clamp(o.fovDeg, 5.0, 150.0);
	// The bounding sphere seen under the vertical field of view: everything is in the picture from
	// any direction (0.8 of it, used before, cut a room seen from above: tests/render).
	const double dist = o.distance.value_or(radius / std::sin(0.5 * fov * M_PI / 180.0));

	std::unique_ptr<mrpt::opengl::CFBORender> fbo;
	try
	{
		fbo = std::make_unique<mrpt::opengl::CFBORender>(o.width, o.height);
	}
	catch (const std::exception& e)
	{
		throw InputError("render", "cannot create an OpenGL context through EGL (" + exceptionSummary(e.what()) + ")");
	}
	auto& cam = fbo->getCamera(scene);
	cam.setProjectiveModel(true);
	cam.setProjectiveFOVdeg(static_cast<float>(fov));
	cam.setPointingAt(o.lookAt.value_or(centre));
	cam.setZoomDistance(static_cast<float>(dist));
	cam.setAzimuthDegrees(static_cast<float>(o.azimuthDeg));
	cam.setElevationDegrees(static_cast<float>(o.elevationDeg));
	mrpt::img::CImage img;
	try
	{
		fbo->render_RGB(scene, img);
	}
	catch (const std::exception& e)
	{
		throw InputError("render", "rendering failed (" + exceptionSummary(e.what()) + ")");
	}
	return img;
}

double nonBackgroundShare(const mrpt::img::CImage& img, const double bg[3])
{
	const cv::Mat m = img.asCvMatRef();
	if (m.empty()) return 0.0;
	const int b = static_cast<int>(std::lround(bg[2] * 255)), g = static_cast<int>(std::lround(bg[1] * 255)),
			  r = static_cast<int>(std::lround(bg[0] * 255));
	std::size_t diff = 0;
	for (int y = 0; y < m.rows; y++)
		for (int x = 0; x < m.cols; x++)
		{
			const cv::Vec3b p = m.channels() == 3 ? m.at<cv::Vec3b>(y, x) : cv::Vec3b::all(m.at<uchar>(y, x));
			if (std::abs(p[0] - b) > 8 || std::abs(p[1] - g) > 8 || std::abs(p[2] - r) > 8) diff++;
		}
	return static_cast<double>(diff) / (static_cast<double>(m.rows) * m.cols);
}

double renderSceneFileToPng(const std::string& scenePath, const std::string& pngPath, const TRenderOptions& opts)
{
	mrpt::opengl::COpenGLScene scene;
	loadScene(scenePath, scene);
	const mrpt::img::CImage img = renderScene(scene, opts);
	writeImageAtomically(pngPath, img.asCvMatRef());
	return nonBackgroundShare(img, opts.background);
}
}  // namespace mrpt_yesslam
