#pragma once
// The simulated office for yesslam-sim: a 6 x 5 x 3 m room with desks, monitors, keyboards, mice,
// chairs, cups, books, bottles, plants and shelves (COCO classes) placed from a seed, and people
// (walking with a gait, or sitting and moving slightly). Every object is a set of textured,
// oriented boxes: CBoxRaycaster renders them (colour, exact depth and instance ids in one pass;
// see there why not CFBORender), and scene() gives the same world as an MRPT scene for viewing.
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/poses/CPose3D.h>

#include "mrpt_yesslam/sim/CBoxRaycaster.h"

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** One box of an object, in the object's frame (centre pose and full extents). */
struct TSimBox
{
	mrpt::poses::CPose3D local;
	double sx = 0.1, sy = 0.1, sz = 0.1;
	int texture = 0;  //!< index into the world's textures
	/** For people: index of the limb whose swing rotates this box (-1 = rigid). */
	int limb = -1;
};

/** An object of the world. */
struct TSimObject
{
	int id = 0;        //!< instance id, 1..65535 (label image value)
	int classId = -1;  //!< COCO class id (0 = person, 56 = chair, ...), -1 = room structure
	std::string name;
	bool moves = false;
	std::vector<TSimBox> boxes;
	mrpt::poses::CPose3D pose;  //!< object frame in the world (z up)
};

/** How people move. */
struct TSimPerson
{
	int object = -1;  //!< index into objects
	bool sitting = false;
	std::vector<mrpt::math::TPoint2D> path;  //!< walking: waypoints on the floor, walked back and forth
	double speed = 1.1;                      //!< m/s
	double phase = 0;                        //!< gait phase offset
	mrpt::poses::CPose3D seat;               //!< sitting: where
};

/** The whole simulated world and its two render scenes. */
class CSimWorld
{
   public:
	/** Builds the room and furniture from `seed`; textures from `photos` if not empty; with
	 * `bareWalls` the walls carry no posters (a lab's painted walls: little to track on them). */
	CSimWorld(uint32_t seed, const std::vector<cv::Mat>& photos = {}, bool bareWalls = false);

	/** Adds a walking person along `path` (world x, y on the floor). */
	void addWalkingPerson(const std::vector<mrpt::math::TPoint2D>& path, double speed, double phase);
	/** Adds a person sitting at `seat` (x, y, yaw), moving head and arms slightly. */
	void addSittingPerson(const mrpt::poses::CPose3D& seat, double phase);
	/** Adds a chair that is pushed along `path` (a non-person dynamic object). */
	void addMovingChair(const std::vector<mrpt::math::TPoint2D>& path, double speed);

	/** Moves the dynamic objects to time `t` (seconds from the start). */
	void setTime(double t);

	/** Every box at the current time, for CBoxRaycaster (textures point into this world). */
	std::vector<TRayBox> rayBoxes() const;
	/** The world as an MRPT scene, lit as the ray caster lights it: the static objects (what
	 * scene.3Dscene holds) or also the moving ones at the current time. */
	mrpt::opengl::COpenGLScene::Ptr scene(bool withMoving = false) const;

	const std::vector<TSimObject>& objects() const { return objects_; }
	/** Object index by instance id (-1 if none). */
	int indexOfId(int id) const;
	/** World pose of every box of an object at the current time, with sizes (for visibility). */
	std::vector<std::pair<mrpt::poses::CPose3D, TSimBox>> worldBoxes(int objectIndex) const;

	static constexpr double kRoomX = 6.0, kRoomY = 5.0, kRoomZ = 3.0;

   private:
	int addObject(TSimObject o);
	int texture(const cv::Scalar& base, int size = 256, double density = 1.0);
	mrpt::opengl::CSetOfObjects::Ptr buildObject(const TSimObject& o) const;
	/** Box poses of a person at time t (animation). */
	void animatePerson(const TSimPerson& p, double t, TSimObject& o) const;

	uint32_t seed_;
	uint32_t texCounter_ = 0;
	std::vector<cv::Mat> textures_;
	std::vector<cv::Mat> photos_;
	std::vector<TSimObject> objects_;
	std::vector<TSimPerson> people_;
	std::vector<std::pair<std::vector<mrpt::math::TPoint2D>, double>> chairPaths_;  // (path, speed) by object
	std::vector<int> chairObjects_;
	double t_ = 0;
};
}  // namespace mrpt_yesslam
