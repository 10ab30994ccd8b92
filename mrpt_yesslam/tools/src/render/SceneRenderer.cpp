#include "mrpt_yesslam/render/SceneRenderer.h"

#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/COpenGLViewport.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/CText.h>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

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
// poses composed; a leaf's own box already includes its pose. Point clouds count by their 1st to
// 99th percentile per axis: a SLAM map's few far points (a window, a stray depth reading) would
// otherwise set the framing and leave the map a speck in the middle of the picture.
bool sceneBounds(const mrpt::opengl::COpenGLScene& scene, mrpt::math::TPoint3D& lo, mrpt::math::TPoint3D& hi,
				 std::vector<mrpt::math::TPoint3D>* samples = nullptr)
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
	std::vector<double> cx, cy, cz;  // every cloud's points (sampled), for their percentiles
	std::vector<mrpt::math::TPoint3D> boxCorners;
	std::function<void(const mrpt::opengl::CRenderizable&, const mrpt::poses::CPose3D&)> add =
		[&](const mrpt::opengl::CRenderizable& o, const mrpt::poses::CPose3D& parent)
	{
		if (!o.isVisible()) return;
		const mrpt::poses::CPose3D pose = parent + mrpt::poses::CPose3D(o.getPose());
		auto addCloud = [&](const auto& pc)
		{
			const std::size_t step = std::max<std::size_t>(1, pc.size() / 100000);
			for (std::size_t i = 0; i < pc.size(); i += step)
			{
				const auto& p = pc.getPoint3Df(i);
				const auto w = pose.composePoint(mrpt::math::TPoint3D(p.x, p.y, p.z));
				if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) continue;
				cx.push_back(w.x), cy.push_back(w.y), cz.push_back(w.z);
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
		if (dynamic_cast<const mrpt::opengl::CText*>(&o)) return;  // drawn at a fixed pixel size: no extent
		try
		{
			const auto bb = o.getBoundingBox();
			// A leaf's box is in its parent's frame already (its own pose applied).
			for (int c = 0; c < 8; c++)
			{
				const auto w = parent.composePoint(mrpt::math::TPoint3D(
					(c & 1) ? bb.max.x : bb.min.x, (c & 2) ? bb.max.y : bb.min.y, (c & 4) ? bb.max.z : bb.min.z));
				grow(w);
				boxCorners.push_back(w);
			}
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
	if (!cx.empty())
	{
		// The 1st and 99th percentile of one axis, from one copy (cx, cy, cz stay aligned).
		auto range = [](std::vector<double> v)
		{
			const bool robust = v.size() >= 200;
			const auto at = [&](double q)
			{
				const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
				std::nth_element(v.begin(), v.begin() + k, v.end());
				return v[static_cast<std::size_t>(k)];
			};
			const double a = at(robust ? 0.01 : 0.0);
			return std::make_pair(a, at(robust ? 0.99 : 1.0));
		};
		const auto [x0, x1] = range(cx);
		const auto [y0, y1] = range(cy);
		const auto [z0, z1] = range(cz);
		grow({x0, y0, z0});
		grow({x1, y1, z1});
	}
	if (samples && any)
	{
		// What the picture must hold: the objects' box corners and the cloud points inside the
		// robust box (at most about 20000 of them).
		*samples = boxCorners;
		const std::size_t step = std::max<std::size_t>(1, cx.size() / 20000);
		for (std::size_t i = 0; i < cx.size(); i += step)
		{
			const mrpt::math::TPoint3D p(cx[i], cy[i], cz[i]);
			if (p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z)
				samples->push_back(p);
		}
	}
	return any;
}

// The legend entries of the visible objects named "legend" (a label's name and colour each).
void collectLegend(const mrpt::opengl::CRenderizable& o, std::vector<std::pair<std::string, mrpt::img::TColor>>& out)
{
	if (const auto* set = dynamic_cast<const mrpt::opengl::CSetOfObjects*>(&o))
	{
		// The legend set itself is hidden (it is drawn over the picture, not in 3D); other hidden
		// objects are not looked into.
		const bool legend = set->getName() == "legend";
		for (const auto& child : *set)
		{
			if (!child) continue;
			const auto* text = dynamic_cast<const mrpt::opengl::CText*>(child.get());
			if (legend && text)
				out.emplace_back(text->getString(), text->getColor_u8());
			else if (!legend && (child->isVisible() || child->getName() == "legend"))
				collectLegend(*child, out);
		}
	}
}

// The legend as an overlay in the picture's top-left corner: a swatch of each colour and its
// name on a pale panel, the same size from any viewpoint (a legend placed in 3D beside the map
// was edge-on or off the picture from above).
void drawLegend(cv::Mat& bgr, const std::vector<std::pair<std::string, mrpt::img::TColor>>& entries)
{
	if (entries.empty() || bgr.empty()) return;
	const double scale = std::clamp(bgr.rows / 700.0, 0.5, 2.0);
	const int line = static_cast<int>(std::lround(24 * scale)), pad = static_cast<int>(std::lround(8 * scale)),
			  sw = static_cast<int>(std::lround(0.7 * line));
	int width = 0;
	for (const auto& [name, c] : entries)
	{
		int base = 0;
		width = std::max(width, cv::getTextSize(name, cv::FONT_HERSHEY_SIMPLEX, 0.6 * scale, 1, &base).width);
	}
	const int w = std::min(bgr.cols, pad * 3 + sw + width),
			  h = std::min(bgr.rows, pad * 2 + line * static_cast<int>(entries.size()));
	cv::Mat roi = bgr(cv::Rect(0, 0, w, h));
	cv::Mat panel(roi.size(), roi.type(), cv::Scalar(250, 250, 250));
	cv::addWeighted(panel, 0.85, roi, 0.15, 0, roi);
	cv::rectangle(bgr, cv::Rect(0, 0, w, h), cv::Scalar(120, 120, 120), 1);
	int y = pad;
	for (const auto& [name, c] : entries)
	{
		const int top = y + (line - sw) / 2;
		cv::rectangle(bgr, cv::Rect(pad, top, sw, sw), cv::Scalar(c.B, c.G, c.R), cv::FILLED);
		cv::rectangle(bgr, cv::Rect(pad, top, sw, sw), cv::Scalar(60, 60, 60), 1);
		cv::putText(bgr, name, cv::Point(2 * pad + sw, top + sw - 1), cv::FONT_HERSHEY_SIMPLEX, 0.6 * scale,
					cv::Scalar(30, 30, 30), 1, cv::LINE_AA);
		y += line;
	}
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
	if (o.hide && !o.hide->empty())
	{
		const auto& hide = *o.hide;
		std::vector<mrpt::opengl::CRenderizable::Ptr> drop;
		for (const auto& obj : *vp)
			if (obj && std::any_of(hide.begin(), hide.end(),
								   [&](const std::string& h) { return !h.empty() && obj->getName().rfind(h, 0) == 0; }))
				drop.push_back(obj);
		for (const auto& obj : drop) vp->removeObject(obj);
	}
	vp->setCustomBackgroundColor(mrpt::img::TColorf(
		static_cast<float>(o.background[0]), static_cast<float>(o.background[1]), static_cast<float>(o.background[2])));

	// Default view: from the nearest distance that keeps all of the scene in the picture from this
	// direction, its picture centred, so that the map fills the picture (a bounding sphere around
	// the box centre, used before, left a flat room a strip in the middle seen from above).
	mrpt::math::TPoint3D centre(0, 0, 0);
	double radius = 1.0;
	mrpt::math::TPoint3D lo, hi;
	std::vector<mrpt::math::TPoint3D> samples;
	if (sceneBounds(scene, lo, hi, &samples))
	{
		const auto d = hi - lo;
		if (d.norm() < 1e6)
		{
			centre = (lo + hi) * 0.5;
			radius = std::max(0.05, 0.5 * d.norm());
		}
		else
			samples.clear();
	}
	const double fov = std::clamp(o.fovDeg, 5.0, 150.0);
	const double az = o.azimuthDeg * M_PI / 180, el = o.elevationDeg * M_PI / 180;
	// MRPT's orbit camera sits at lookAt + D (cos el cos az, cos el sin az, sin el).
	const Eigen::Vector3d back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
	Eigen::Vector3d right = Eigen::Vector3d::UnitZ().cross(back);
	if (right.norm() < 1e-6) right = Eigen::Vector3d(-std::sin(az), std::cos(az), 0);
	right.normalize();
	const Eigen::Vector3d up = back.cross(right);
	const double tv = std::tan(0.5 * fov * M_PI / 180), th = tv * o.width / o.height;
	Eigen::Vector3d target(centre.x, centre.y, centre.z);
	if (o.lookAt) target = Eigen::Vector3d(o.lookAt->x, o.lookAt->y, o.lookAt->z);
	// A point q (from the target) is inside the picture of a camera at distance D while
	// |q.right| <= th (D - q.back) and |q.up| <= tv (D - q.back).
	auto fitDistance = [&]
	{
		double D = 0;
		for (const auto& p : samples)
		{
			const Eigen::Vector3d q = Eigen::Vector3d(p.x, p.y, p.z) - target;
			D = std::max({D, std::abs(q.dot(right)) / th + q.dot(back), std::abs(q.dot(up)) / tv + q.dot(back)});
		}
		return std::max(1.04 * D, 0.1);
	};
	double dist = samples.empty() ? radius / std::sin(0.5 * fov * M_PI / 180.0) : fitDistance();
	// Centre the picture on what it shows (the box centre is not the picture's centre in
	// perspective, nor when the box holds empty space): move the target by the middle of the
	// points' image extent, then fit again.
	for (int it = 0; it < 3 && !samples.empty() && !o.lookAt; it++)
	{
		double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
		for (const auto& p : samples)
		{
			const Eigen::Vector3d q = Eigen::Vector3d(p.x, p.y, p.z) - target;
			const double depth = std::max(1e-6, dist - q.dot(back));
			u0 = std::min(u0, q.dot(right) / depth), u1 = std::max(u1, q.dot(right) / depth);
			v0 = std::min(v0, q.dot(up) / depth), v1 = std::max(v1, q.dot(up) / depth);
		}
		target += dist * (0.5 * (u0 + u1) * right + 0.5 * (v0 + v1) * up);
		dist = fitDistance();
	}
	if (o.distance) dist = *o.distance;

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
	cam.setPointingAt(mrpt::math::TPoint3D(target.x(), target.y(), target.z()));
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
	std::vector<std::pair<std::string, mrpt::img::TColor>> legend;
	for (const auto& obj : *vp)
		if (obj && obj->isVisible()) collectLegend(*obj, legend);
	if (!legend.empty())
	{
		drawLegend(img.asCvMatRef(), legend);
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

std::vector<std::string> defaultHidden(const mrpt::opengl::COpenGLScene& scene)
{
	const auto vp = scene.getViewport("main");
	if (!vp) return {};
	bool octomap = false, dense = false;
	for (const auto& obj : *vp)
		if (obj) octomap |= obj->getName() == "octomap", dense |= obj->getName() == "dense_cloud";
	if (octomap && dense) return {"octomap"};
	return {};
}

double renderSceneFileToPng(const std::string& scenePath, const std::string& pngPath, const TRenderOptions& opts)
{
	mrpt::opengl::COpenGLScene scene;
	loadScene(scenePath, scene);
	TRenderOptions o = opts;
	if (!o.hide) o.hide = defaultHidden(scene);
	const mrpt::img::CImage img = renderScene(scene, o);
	makeParentFolder(pngPath);
	writeImageAtomically(pngPath, img.asCvMatRef());
	return nonBackgroundShare(img, opts.background);
}
}  // namespace mrpt_yesslam
