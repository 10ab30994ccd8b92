#pragma once
// Headless rendering of .3Dscene files to PNG through MRPT's CFBORender (EGL, no X server): how
// users and tests look at maps on machines without a display.
#include <mrpt/opengl/COpenGLScene.h>

#include <optional>
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** Image size and the orbit camera that looks at the scene. */
struct TRenderOptions
{
	unsigned width = 1024, height = 768;
	/** Around the vertical (z) axis. 200: a yesslam map seen from behind its first camera (its
	 * world x axis is that camera's view), a little from the side. */
	double azimuthDeg = 200.0;
	double elevationDeg = 35.0;                  //!< above the horizon
	std::optional<double> distance;              //!< metres from the look-at point; default fits the scene
	std::optional<mrpt::math::TPoint3D> lookAt;  //!< default: centre of the scene's bounding box
	double fovDeg = 60.0;                        //!< vertical field of view
	double background[3] = {1.0, 1.0, 1.0};      //!< RGB in [0,1]
	/** Top-level objects whose name starts with one of these are left out (yesslam-sim names its
	 * objects: "ceiling", "wall near", ... so that a room can be seen from inside). Unset:
	 * renderSceneFileToPng leaves out defaultHidden(scene); renderScene nothing. */
	std::optional<std::vector<std::string>> hide;
};

/** What a picture of `scene` leaves out unless told otherwise: a yesslam run's OctoMap voxels when
 * the scene also holds its dense cloud (they would cover it; --hide dense_cloud,map_points,keyframe
 * shows the OctoMap instead). */
std::vector<std::string> defaultHidden(const mrpt::opengl::COpenGLScene& scene);

/** Loads a .3Dscene file; throws InputError naming it when missing or not a scene. */
void loadScene(const std::string& path, mrpt::opengl::COpenGLScene& scene);

/** Renders `scene` into a BGR cv::Mat-compatible CImage. Throws InputError("render: ...") when no
 * EGL/OpenGL context can be created. */
mrpt::img::CImage renderScene(mrpt::opengl::COpenGLScene& scene, const TRenderOptions& opts);

/** Loads, renders and writes a PNG atomically. Returns the share of pixels that differ from the
 * background (0 = blank picture). `opts.hide` unset: defaultHidden(scene). */
double renderSceneFileToPng(const std::string& scenePath, const std::string& pngPath, const TRenderOptions& opts);

/** Share of pixels of a BGR image that differ from the background colour by more than 8/255. */
double nonBackgroundShare(const mrpt::img::CImage& img, const double background[3]);
}  // namespace mrpt_yesslam
