#pragma once
// Builds a viewable 3D scene from RGB-D frames placed at known poses (ground truth, or later our
// own estimate): a coloured point cloud in the world frame, the camera path and camera axes.
// If the poses and the camera model agree, the clouds of all frames overlap into one clean
// surface, so this is also a quick check of a dataset's conventions.
#include <mrpt/opengl/COpenGLScene.h>

#include <functional>
#include <string>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/Trajectory.h"

namespace mrpt_yesslam
{
/** What to put into the scene. */
struct TSceneExportOptions
{
	int pixelStride = 4;        //!< use every n-th pixel in x and y
	double maxDepth = 4.0;      //!< metres; farther depth is noisy on Kinect-type sensors
	double maxTimeDiff = 0.02;  //!< a frame needs a pose within this many seconds
	std::size_t maxFrames = 0;  //!< 0 = all
	std::size_t frameStep = 1;  //!< use every n-th frame
	float pointSize = 2.0f;
};

/** Result of an export. */
struct TSceneExportSummary
{
	std::size_t framesUsed = 0, framesWithoutPose = 0, points = 0;
};

/** Back-projects every used frame with its pose (camera-to-world, optical frame: z forward, as in
 * TUM) and builds the scene. Throws InputError when no frame has a pose. */
mrpt::opengl::COpenGLScene::Ptr buildPosedCloudScene(CInputSource& src, const TTrajectory& poses,
													 const TSceneExportOptions& opts, TSceneExportSummary& summary,
													 const std::function<void(std::size_t)>& progress = {});

/** Saves a scene atomically (temp file + rename); throws InputError naming the file. */
void saveSceneAtomically(const mrpt::opengl::COpenGLScene& scene, const std::string& path);
}  // namespace mrpt_yesslam
