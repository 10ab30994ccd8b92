#include "mrpt_yesslam/sim/SimPresets.h"

#include <mrpt/math/CMatrixDynamic.h>

#include <cmath>

#include "mrpt_yesslam/sim/CSequenceSimulator.h"

namespace mrpt_yesslam
{
using mrpt::poses::CPose3D;

const std::vector<TSimPreset>& simPresets()
{
	static const std::vector<TSimPreset> p = {
		{"walking_xyz",
		 "two people walk through the view, one close; camera translates along x, y, z (fr3/walking_xyz)", "xyz", 2, 0,
		 900},
		{"walking_static",
		 "two people walk through the view; camera still up to millimetre jitter (fr3/walking_static)", "static", 2, 0,
		 900},
		{"walking_rpy", "two people walk through the view; camera rotates in roll, pitch, yaw (fr3/walking_rpy)", "rpy",
		 2, 0, 900},
		{"walking_halfsphere",
		 "two people walk through the view; camera moves on a half sphere (fr3/walking_halfsphere)", "halfsphere", 2, 0,
		 900},
		{"sitting_static", "two people sit at desks, moving head and arms; camera still (fr3/sitting_static)", "static",
		 0, 2, 600},
		{"sitting_xyz", "two people sit at desks; camera translates along x, y, z (fr3/sitting_xyz)", "xyz", 0, 2, 900},
		{"sitting_rpy", "two people sit at desks; camera rotates in roll, pitch, yaw (fr3/sitting_rpy)", "rpy", 0, 2,
		 900},
		{"sitting_halfsphere", "two people sit at desks; camera moves on a half sphere (fr3/sitting_halfsphere)",
		 "halfsphere", 0, 2, 900},
		{"static_office", "the office without people; camera translates along x, y, z (a static reference)", "xyz", 0,
		 0, 600},
		{"office_loop",
		 "one person walks; camera goes round a small loop, never losing sight of its start (back there after 24 s)",
		 "loop", 1, 0, 900},
		{"office_tour",
		 "two people walk; camera turns round the room centre looking at every wall, back at its start every 16 s from "
		 "a little further out, 2.5 turns (loop closure)",
		 "tour", 2, 0, 1200},
		{"static_tour", "the office_tour camera path without people (loop closure in a static room)", "tour", 0, 0,
		 1200},
		// What the simulator lacked beside the real Bonn "crowd" frames (issue 27): bare walls, a slow
		// hand-held pan, three people passing within a metre, the real sensor.
		{"crowd",
		 "three people walk past within a metre of a hand-held camera panning slowly over bare walls and desks 2-5 m "
		 "away "
		 "(Bonn RGB-D Dynamic crowd); the real sensor model (--real-sensor) on",
		 "pan", 3, 0, 900, true, true,
		 // Its colour and depth images up to 16.7 ms apart, drifting, as the real Bonn frames' are (the two streams of
		 // their Xtion run free); without it the double was much easier than the real slice (issue 39 item 6).
		 16.7},
	};
	return p;
}

// Camera at the near end of the room looking along +x, 8 degrees down; optical frame z forward,
// x right, y down (as TUM and MRPT's 6-DoF camera).
CPose3D basePose()
{
	mrpt::math::CMatrixDouble33 R;
	const double a = -8.0 * M_PI / 180;  // rotation about the camera x axis: negative looks down
	const Eigen::Vector3d xc(0, -1, 0), yc0(0, 0, -1), zc0(1, 0, 0);
	const Eigen::Vector3d zc = std::cos(a) * zc0 - std::sin(a) * yc0;
	const Eigen::Vector3d yc = zc.cross(xc);
	for (int i = 0; i < 3; i++)
	{
		R(i, 0) = xc[i];
		R(i, 1) = yc[i];
		R(i, 2) = zc[i];
	}
	mrpt::math::CVectorFixedDouble<3> t;
	t[0] = 1.8;  // the far wall 4.2 m away: within a Kinect's range
	t[1] = 2.5;
	t[2] = 1.3;
	return CPose3D(R, t);
}

// Motion of the camera relative to the base pose, in the camera frame, at time t.
CPose3D presetMotion(const std::string& motion, double t, uint32_t seed)
{
	const double s = 2 * M_PI;
	if (motion == "xyz")
		return CPose3D(0.28 * std::sin(s * t / 7.0), 0.16 * std::sin(s * t / 5.3), 0.25 * std::sin(s * t / 9.1), 0, 0,
					   0);
	if (motion == "rpy")
		return CPose3D(0.03 * std::sin(s * t / 6), 0.02 * std::sin(s * t / 7), 0, 0.35 * std::sin(s * t / 8),
					   0.2 * std::sin(s * t / 6.5), 0.25 * std::sin(s * t / 10));
	if (motion == "halfsphere")
	{
		// On a sphere of radius 1 m around a point 2 m ahead, always looking at it.
		const double az = 0.9 * std::sin(s * t / 14), el = 0.35 * (1 - std::cos(s * t / 11));
		const Eigen::Vector3d c(0, 0, 2.0);
		const Eigen::Vector3d p =
			c + Eigen::Vector3d(std::sin(az) * std::cos(el), -std::sin(el), -std::cos(az) * std::cos(el));
		const Eigen::Vector3d z = (c - p).normalized(), x = Eigen::Vector3d(0, 1, 0).cross(z).normalized(),
							  y = z.cross(x);
		mrpt::math::CMatrixDouble33 R;
		for (int i = 0; i < 3; i++)
		{
			R(i, 0) = x[i];
			R(i, 1) = y[i];
			R(i, 2) = z[i];
		}
		mrpt::math::CVectorFixedDouble<3> tv;
		for (int i = 0; i < 3; i++) tv[i] = p[i] - (c - Eigen::Vector3d(0, 0, 1.0))[i];
		return CPose3D(R, tv);
	}
	if (motion == "tour")
	{
		// A full turn in 16 s (22 degrees/s, a handheld pace) on a circle round (2.6, 2.5), looking
		// outwards (8 degrees down) at each wall in turn: after about a third of the turn the start
		// is out of sight, so only loop closing can tie the end of the turn to its start. The radius
		// grows slowly (0.45 m at the start, 0.52 m a turn later), so each place is seen again from
		// a slightly different viewpoint; 1200 frames make two and a half turns.
		const double th = s * t / 16.0, r = 0.45 + 0.0044 * t, a = -8.0 * M_PI / 180;
		const Eigen::Vector3d p(2.6 + r * std::cos(th), 2.5 + r * std::sin(th), 1.3 + 0.05 * std::sin(s * t / 6.5));
		const Eigen::Vector3d z(std::cos(a) * std::cos(th), std::cos(a) * std::sin(th), std::sin(a)),
			x(std::sin(th), -std::cos(th), 0);
		const Eigen::Vector3d y = z.cross(x);
		mrpt::math::CMatrixDouble33 R;
		mrpt::math::CVectorFixedDouble<3> tv;
		for (int i = 0; i < 3; i++)
		{
			R(i, 0) = x[i];
			R(i, 1) = y[i];
			R(i, 2) = z[i];
			tv[i] = p[i];
		}
		return -basePose() + CPose3D(R, tv);  // relative to the base pose, as the other motions
	}
	if (motion == "pan")
	{
		// Hand-held: a slow pan left and right (+-26 degrees, at most 9 degrees/s) about the camera's
		// vertical axis, a slow drift forward and sideways (at most 0.1 m/s: 3 mm a frame, as the
		// Bonn crowd camera), and hand tremor of a few millimetres and a few tenths of a degree.
		const double pan = 0.45 * std::sin(s * t / 18.0), k = seed * 0.53;
		return CPose3D(0.15 * std::sin(s * t / 11.0) + 0.002 * std::sin(s * 2.3 * t + k),
					   0.0015 * std::sin(s * 3.7 * t + 2 * k), 0.25 * std::sin(s * t / 15.0),
					   0.004 * std::sin(s * 1.9 * t + 3 * k), pan, 0.003 * std::sin(s * 2.9 * t + k));
	}
	if (motion == "loop")
	{
		// Round a 1.6 x 1.0 m ellipse in 24 s, turning to look at the room's sides, back at the start.
		const double ph = s * t / 24.0;
		return CPose3D(0.8 * std::sin(ph), 0, 0.5 * (1 - std::cos(ph)), 0, 0, 0) +
			   CPose3D(0, 0, 0, 0.5 * std::sin(ph), 0, 0);
	}
	// static: millimetre jitter, as a camera on a tripod on a shaking floor.
	const double k = seed * 0.37;
	return CPose3D(0.001 * std::sin(17.3 * t + k), 0.001 * std::sin(13.1 * t + 2 * k),
				   0.001 * std::sin(11.7 * t + 3 * k), 0.0005 * std::sin(9.1 * t), 0.0005 * std::sin(7.3 * t),
				   0.0005 * std::sin(5.9 * t));
}
}  // namespace mrpt_yesslam
