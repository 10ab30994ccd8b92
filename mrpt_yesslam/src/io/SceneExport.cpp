#include "mrpt_yesslam/io/SceneExport.h"

#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/stock_objects.h>

#include <algorithm>
#include <cmath>

#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
mrpt::opengl::COpenGLScene::Ptr buildPosedCloudScene(CInputSource& src, const TTrajectory& posesIn,
													 const TSceneExportOptions& o, TSceneExportSummary& sum,
													 const std::function<void(std::size_t)>& progress)
{
	const TTrajectory poses = uniqueSortedByTime(posesIn);
	if (poses.empty()) throw InputError("", "no poses to place the frames with");
	std::vector<double> stamps;
	for (const auto& p : poses) stamps.push_back(p.t);

	auto scene = mrpt::opengl::COpenGLScene::Create();
	auto cloud = mrpt::opengl::CPointCloudColoured::Create();
	cloud->setPointSize(o.pointSize);
	auto path = mrpt::opengl::CSetOfLines::Create();
	path->setColor_u8(20, 20, 20);
	path->setLineWidth(2.0f);
	const int stride = std::max(1, o.pixelStride);
	std::size_t index = 0;
	bool havePrev = false;
	mrpt::math::TPoint3D prev;
	while (auto obs = src.next())
	{
		if (o.maxFrames && sum.framesUsed >= o.maxFrames) break;
		if (progress) progress(index + 1);
		if (index++ % std::max<std::size_t>(1, o.frameStep) != 0) continue;
		const double t = observationTime(*obs);
		const auto it = std::lower_bound(stamps.begin(), stamps.end(), t);
		std::size_t best = stamps.size();
		for (auto c : {it, it == stamps.begin() ? it : it - 1})
			if (c != stamps.end() && (best == stamps.size() || std::abs(*c - t) < std::abs(stamps[best] - t)))
				best = static_cast<std::size_t>(c - stamps.begin());
		if (best == stamps.size() || std::abs(stamps[best] - t) > o.maxTimeDiff)
		{
			sum.framesWithoutPose++;
			continue;
		}
		const mrpt::poses::CPose3D T = poses[best].asPose();
		const auto& K = obs->cameraParamsIntensity;
		const cv::Mat img = obs->intensityImage.asCvMatRef();
		for (int v = 0; v < obs->rangeImage.rows(); v += stride)
			for (int u = 0; u < obs->rangeImage.cols(); u += stride)
			{
				const double z = obs->rangeImage(v, u) * static_cast<double>(obs->rangeUnits);
				if (z <= 0 || z > o.maxDepth) continue;
				const mrpt::math::TPoint3D pc((u - K.cx()) * z / K.fx(), (v - K.cy()) * z / K.fy(), z);
				const auto pw = T.composePoint(pc);
				const cv::Vec3b bgr =
					img.channels() == 3 ? img.at<cv::Vec3b>(v, u) : cv::Vec3b::all(img.at<uchar>(v, u));
				cloud->push_back(static_cast<float>(pw.x), static_cast<float>(pw.y), static_cast<float>(pw.z),
								 bgr[2] / 255.f, bgr[1] / 255.f, bgr[0] / 255.f);
				sum.points++;
			}
		const mrpt::math::TPoint3D c(T.x(), T.y(), T.z());
		if (havePrev) path->appendLine(prev, c);
		prev = c;
		havePrev = true;
		auto axes = mrpt::opengl::stock_objects::CornerXYZSimple(0.1f, 2.0f);
		axes->setPose(T);
		scene->insert(axes);
		sum.framesUsed++;
	}
	if (sum.framesUsed == 0)
		throw InputError(src.path(), "no frame has a pose within " + std::to_string(o.maxTimeDiff) + " s");
	scene->insert(cloud);
	scene->insert(path);
	return scene;
}

void saveSceneAtomically(const mrpt::opengl::COpenGLScene& scene, const std::string& path)
{
	writeFileAtomically(path,
						[&](const std::string& tmp)
						{
							if (!scene.saveToFile(tmp)) throw InputError(path, "cannot write scene");
						});
}
}  // namespace mrpt_yesslam
