// yesslam-render: renders a .3Dscene file to PNG headless (EGL), for looking at maps without a GUI.
#include <cstdio>

#include "mrpt_yesslam/render/SceneRenderer.h"
#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-render",
		[&]() -> int
		{
			std::string scenePath, outPath, lookAt, background;
			std::size_t width = 1024, height = 768;
			double distance = 0;
			TRenderOptions o;
			CommandLine cl(
				"yesslam-render", "yesslam-render --scene MAP.3Dscene --out MAP.png [options]",
				"Renders an MRPT .3Dscene (maps written by yesslam, scenes by yesslam-sim) to a PNG with MRPT's\n"
				"CFBORender through EGL: no X server or display is needed. The camera orbits the look-at point:\n"
				"azimuth around the vertical (z) axis, elevation above the horizon, at the given distance; by default\n"
				"it looks at the centre of the scene from as near as keeps all of it in the picture. A yesslam map\n"
				"shows its dense cloud, map points, keyframes and trajectory (red); with its OctoMap shown (--hide\n"
				"dense_cloud,map_points,keyframe) the label legend is drawn in the top-left corner.",
				{"yesslam-render --scene out/map.3Dscene --out map.png",
				 "yesslam-render --scene map.3Dscene --out top.png --elevation 89 --width 1600 --height 1200",
				 "yesslam-render --scene sim/scene.3Dscene --out inside.png --hide ceiling,wall --elevation 50"});
			cl.text("scene", "FILE", ".3Dscene file to render", &scenePath, true);
			cl.text("out", "FILE", "image to write (atomically): PNG, or JPEG for a .jpg/.jpeg name", &outPath, true);
			cl.count("width", "PX", "image width", &width);
			cl.count("height", "PX", "image height", &height);
			cl.number("azimuth", "DEG",
					  "camera azimuth around the vertical axis [default: 200: a yesslam map from behind its first "
					  "camera, whose view is the map's x axis]",
					  &o.azimuthDeg);
			cl.number("elevation", "DEG", "camera elevation above the horizon (90 = top-down)", &o.elevationDeg);
			cl.number("distance", "M", "camera distance to the look-at point [default: fits the whole scene]",
					  &distance);
			cl.text("look-at", "X,Y,Z", "point the camera looks at [default: centre of the scene]", &lookAt);
			cl.number("fov", "DEG", "vertical field of view", &o.fovDeg);
			cl.text("background", "R,G,B", "background colour, components in 0..1 [default: 1,1,1 (white)]",
					&background);
			std::string hide;
			cl.text("hide", "NAMES",
					"comma-separated: leave out objects whose name starts with one of these (yesslam maps: "
					"dense_cloud, octomap, map_points, keyframe, "
					"trajectory; yesslam-sim scenes: ceiling, wall, desk, ...); none: show everything [default: a "
					"yesslam map's octomap, which would "
					"cover its dense cloud]",
					&hide);
			if (!cl.parse(argc, argv)) return 0;
			if (cl.given("hide"))
			{
				o.hide.emplace();
				for (std::size_t a = 0; hide != "none" && a <= hide.size();)
				{
					const auto b = std::min(hide.find(',', a), hide.size());
					if (b > a) o.hide->push_back(hide.substr(a, b - a));
					a = b + 1;
				}
			}
			o.width = static_cast<unsigned>(width);
			o.height = static_cast<unsigned>(height);
			if (cl.given("distance"))
			{
				if (!(distance > 0)) throw InputError("", "--distance must be positive");
				o.distance = distance;
			}
			auto parse3 = [](const std::string& s, const char* opt, double v[3])
			{
				const auto f = splitFields(s);
				if (f.size() != 3 || !parseFiniteDouble(f[0], v[0]) || !parseFiniteDouble(f[1], v[1]) ||
					!parseFiniteDouble(f[2], v[2]))
					throw InputError("", std::string("--") + opt + " expects three numbers 'a,b,c', got '" + s + "'");
			};
			if (!lookAt.empty())
			{
				double v[3];
				parse3(lookAt, "look-at", v);
				o.lookAt = mrpt::math::TPoint3D(v[0], v[1], v[2]);
			}
			if (!background.empty())
			{
				parse3(background, "background", o.background);
				for (double c : o.background)
					if (!(c >= 0 && c <= 1))
						throw InputError("",
										 "--background components are in 0..1 (not 0..255), got '" + background + "'");
			}
			if (!(o.fovDeg > 0 && o.fovDeg < 180))
				throw InputError("", "--fov must be between 0 and 180 degrees (exclusive)");
			if (!(o.elevationDeg >= -90 && o.elevationDeg <= 90))
				throw InputError("", "--elevation must be in -90..90 degrees");
			const double share = renderSceneFileToPng(scenePath, outPath, o);
			std::printf("wrote %s (%ux%u, %.1f%% of pixels show the scene)\n", outPath.c_str(), o.width, o.height,
						100.0 * share);
			// Almost nothing in view (a few stray pixels of a far object): as useless as a blank picture.
			if (share < 0.005)
				std::fprintf(stderr,
							 "yesslam-render: warning: the picture is %s; check --look-at, --distance, --azimuth and "
							 "--elevation\n",
							 share == 0.0 ? "blank" : "almost blank (under 0.5% of pixels show the scene)");
			return 0;
		});
}
