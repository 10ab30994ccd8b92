// The sparse map's own operations: stable ids, the stored covisibility graph (checked against a
// recount from the observations after every kind of change), the spanning tree, keyframe erasure
// and redundant-keyframe culling, point fusion, the recent-points list, the generation counter
// that refuses stale bundle results, and the versioned serialisation of keyframes and points.
#include <gtest/gtest.h>

#include <cstring>
#include <Eigen/Dense>
#include <mrpt/math/CMatrixFixed.h>

#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>

#include "TestUtils.h"
#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/util/BinaryIO.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
std::vector<mrpt::math::TPoint3D> wall(int n, double z = 2.5)
{
	std::vector<mrpt::math::TPoint3D> w;
	for (int i = 0; i < n; i++)
		w.emplace_back(-1.0 + 2.0 * (i % 10) / 9.0, -0.7 + 1.4 * (i / 10) / 9.0, z + 0.01 * (i % 7));
	return w;
}

// Keyframe `id` at `pose` observing the points `ids` of `world` (-1: creates a new point from depth).
TKeyFrameId addView(CSparseMap& map, std::size_t id, const mrpt::poses::CPose3D& pose,
					const std::vector<mrpt::math::TPoint3D>& world, const std::vector<TPointId>& ids, std::mt19937& rng,
					int octave = 0)
{
	return map.addKeyFrame(observeWorld(id, pose, world, ids, rng, octave), 10.0);
}

// The covisibility weights recounted from the observations of the good points.
std::map<std::pair<TKeyFrameId, TKeyFrameId>, int> recount(const CSparseMap& map)
{
	std::map<std::pair<TKeyFrameId, TKeyFrameId>, int> w;
	for (const auto& p : map.points())
		for (const auto& [a, ia] : p.observations)
			for (const auto& [b, ib] : p.observations)
				if (a != b) w[{a, b}]++;
	return w;
}

void expectGraphMatchesObservations(const CSparseMap& map)
{
	const auto expected = recount(map);
	std::map<std::pair<TKeyFrameId, TKeyFrameId>, int> stored;
	for (TKeyFrameId k : map.keyFrameIds())
	{
		const CKeyFrame kf = map.keyFrame(k);
		for (const auto& [o, w] : kf.connections) stored[{k, o}] = w;
		// The ordered list is the connections, heaviest first.
		ASSERT_EQ(kf.orderedConnections.size(), kf.connections.size());
		for (std::size_t i = 1; i < kf.orderedConnections.size(); i++)
			EXPECT_GE(kf.weight(kf.orderedConnections[i - 1]), kf.weight(kf.orderedConnections[i]));
	}
	EXPECT_EQ(stored, expected);
}

std::vector<TPointId> range(TPointId from, TPointId to)
{
	std::vector<TPointId> v;
	for (TPointId i = from; i < to; i++) v.push_back(i);
	return v;
}
}  // namespace

TEST(SparseMap, CovisibilityGraphAndSpanningTreeAreStoredAndUpdated)
{
	std::mt19937 rng(1);
	const auto world = wall(100);
	CSparseMap map;
	// kf0 creates points 0-99; kf1 sees 0-59; kf2 sees 40-99 (shares 20 with kf1, 60 with kf0).
	std::vector<TPointId> none(100, -1), ids1(100, -1), ids2(100, -1);
	for (int j = 0; j < 60; j++) ids1[j] = j;
	for (int j = 40; j < 100; j++) ids2[j] = j;
	EXPECT_EQ(addView(map, 0, {}, world, none, rng), 0u);
	EXPECT_EQ(addView(map, 1, mrpt::poses::CPose3D(0.05, 0, 0, 0, 0, 0), world, ids1, rng), 1u);
	EXPECT_EQ(addView(map, 2, mrpt::poses::CPose3D(-0.05, 0, 0, 0, 0, 0), world, ids2, rng), 2u);
	const CKeyFrame k0 = map.keyFrame(0), k1 = map.keyFrame(1), k2 = map.keyFrame(2);
	EXPECT_EQ(k0.weight(1), 60);
	EXPECT_EQ(k0.weight(2), 60);
	EXPECT_EQ(k1.weight(2), 20);
	EXPECT_EQ(map.covisible(1, 5), (std::vector<TKeyFrameId>{0, 2}));
	EXPECT_EQ(map.covisible(1, 5, 30), (std::vector<TKeyFrameId>{0}));
	// Spanning tree: each keyframe under the one it shares most with.
	EXPECT_FALSE(k0.parent.has_value());
	EXPECT_EQ(*k1.parent, 0u);
	EXPECT_EQ(*k2.parent, 0u);
	EXPECT_EQ(k0.children, (std::set<TKeyFrameId>{1, 2}));
	expectGraphMatchesObservations(map);
	// Points leave: the weights follow without a rescan.
	for (TPointId p = 40; p < 50; p++) map.erasePoint(p);
	EXPECT_EQ(map.keyFrame(1).weight(2), 10);
	EXPECT_EQ(map.keyFrame(0).weight(1), 50);
	expectGraphMatchesObservations(map);
}

TEST(SparseMap, ReplacingAPointMovesEveryObservation)
{
	std::mt19937 rng(2);
	const auto world = wall(30);
	CSparseMap map;
	addView(map, 0, {}, world, std::vector<TPointId>(30, -1), rng);  // points 0-29
	// kf1 sees 0-9 and creates a duplicate of point 5's place (a new point) at keypoint 20.
	std::vector<TPointId> ids(30, -1);
	for (int j = 0; j < 10; j++) ids[j] = j;
	addView(map, 1, mrpt::poses::CPose3D(0.05, 0, 0, 0, 0, 0), world, ids, rng);
	const CKeyFrame k1 = map.keyFrame(1);
	const TPointId duplicate = k1.mapPoints[20];
	ASSERT_GE(duplicate, 30);
	const std::size_t before = map.numPoints();
	// Fuse kf0's point 20 (seen by kf0 only) into kf1's duplicate.
	ASSERT_TRUE(map.replacePoint(20, duplicate));
	EXPECT_EQ(map.numPoints(), before - 1);
	const CMapPoint fused = map.point(duplicate), old = map.point(20);
	EXPECT_TRUE(old.bad);
	EXPECT_EQ(old.replacedBy, duplicate);
	EXPECT_TRUE(old.observations.empty());
	EXPECT_EQ(fused.observations.size(), 2u);
	EXPECT_EQ(map.keyFrame(0).mapPoints[20], duplicate);
	// Tracking that still holds the old id gets the new point.
	EXPECT_EQ(map.pointsById({20}).ids, std::vector<TPointId>{duplicate});
	// kf0 and kf1 share one more point now.
	EXPECT_EQ(map.keyFrame(0).weight(1), 11);
	expectGraphMatchesObservations(map);
	EXPECT_FALSE(map.replacePoint(20, duplicate));  // already fused
}

TEST(SparseMap, ErasingAKeyFrameRehangsItsChildrenAndKeepsItsPose)
{
	std::mt19937 rng(3);
	const auto world = wall(60);
	CSparseMap map;
	addView(map, 0, {}, world, std::vector<TPointId>(60, -1), rng);
	std::vector<TPointId> all = range(0, 60);
	const mrpt::poses::CPose3D p1(0.1, 0, 0, 0.02, 0, 0), p2(0.2, 0, 0, 0, 0, 0), p3(0.3, 0, 0, 0, 0, 0);
	addView(map, 1, p1, world, all, rng);
	// kf2 shares all with kf0 and kf1 but the tree hangs it under the heaviest, the oldest on ties.
	addView(map, 2, p2, world, all, rng);
	ASSERT_EQ(*map.keyFrame(2).parent, 0u);
	EXPECT_FALSE(map.eraseKeyFrame(0));  // the root anchors the map
	ASSERT_TRUE(map.eraseKeyFrame(1));
	EXPECT_FALSE(map.eraseKeyFrame(1));
	EXPECT_TRUE(map.isBad(1));
	EXPECT_EQ(map.numKeyFrames(), 2u);
	EXPECT_EQ(map.keyFrameIds(), (std::vector<TKeyFrameId>{0, 2}));
	// Its pose still resolves (frames tracked from it keep their place) and follows its parent.
	EXPECT_NEAR((map.keyFramePose(1) - p1).norm(), 0, 1e-9);
	EXPECT_EQ(map.goodAncestor(1), 0u);
	// New keyframes keep counting up: ids are not positions.
	EXPECT_EQ(addView(map, 3, p3, world, all, rng), 3u);
	EXPECT_EQ(map.keyFrame(0).weight(1), 0);
	EXPECT_EQ(map.keyFrame(0).weight(3), 60);
	expectGraphMatchesObservations(map);

	// A keyframe with children: erasing kf2 re-hangs kf3 (which shares points with kf0).
	ASSERT_EQ(*map.keyFrame(3).parent, 0u);
	std::vector<TPointId> five(60, -1);
	for (int j = 0; j < 5; j++) five[j] = j;
	addView(map, 4, p3, world, five, rng);  // creates points 60-114, kf4's children follow it
	std::vector<TPointId> fromKf4(60, -1);
	for (int j = 5; j < 60; j++) fromKf4[j] = map.keyFrame(4).mapPoints[j];
	addView(map, 5, p3, world, fromKf4, rng);
	ASSERT_EQ(*map.keyFrame(5).parent, 4u);
	ASSERT_TRUE(map.eraseKeyFrame(4));
	// kf5 shared nothing else with kf4's parent: it goes to the parent, and its points survive (it sees them).
	EXPECT_EQ(*map.keyFrame(5).parent, *map.keyFrame(4).parent);
	EXPECT_TRUE(map.keyFrame(*map.keyFrame(5).parent).children.count(5));
	expectGraphMatchesObservations(map);
}

// A root keyframe making 80 points of a wall, and five more at almost the same place seeing them all.
static void sixViewsOfOneWall(CSparseMap& map, std::mt19937& rng)
{
	const auto world = wall(80);
	addView(map, 0, {}, world, std::vector<TPointId>(80, -1), rng);
	for (std::size_t k = 1; k <= 5; k++)
		addView(map, k, mrpt::poses::CPose3D(0.01 * k, 0, 0, 0, 0, 0), world, range(0, 80), rng);
}

TEST(SparseMap, RedundantKeyFramesAreCulled)
{
	// Five keyframes at almost the same place see the same points: all but the root, the newest and
	// enough to keep each point seen three times are redundant (ORB-SLAM2's rule).
	std::mt19937 rng(4);
	const auto world = wall(80);
	CSparseMap map;
	sixViewsOfOneWall(map, rng);
	const auto erased = map.cullRedundantKeyFrames(5, 0.9, 3, 10.0);
	// Checked oldest first (equal weights): kf1, kf2 and kf3 each still had three other observers
	// of every point when their turn came; kf4 then had two (kf0, kf5) and stays.
	EXPECT_EQ(erased, (std::vector<TKeyFrameId>{1, 2, 3}));
	EXPECT_EQ(map.keyFrameIds(), (std::vector<TKeyFrameId>{0, 4, 5}));
	for (const auto& p : map.points()) EXPECT_EQ(p.observations.size(), 3u);
	EXPECT_TRUE(map.cullRedundantKeyFrames(5, 0.9, 3, 10.0).empty());
	expectGraphMatchesObservations(map);

	// A keyframe seen only at coarser scales by the others is not redundant.
	CSparseMap fine;
	addView(fine, 0, {}, world, std::vector<TPointId>(80, -1), rng, 0);
	addView(fine, 1, mrpt::poses::CPose3D(0.01, 0, 0, 0, 0, 0), world, range(0, 80), rng, 0);
	for (std::size_t k = 2; k <= 5; k++)
		addView(fine, k, mrpt::poses::CPose3D(0.01 * k, 0, 0, 0, 0, 0), world, range(0, 80), rng, 3);
	const auto none = fine.cullRedundantKeyFrames(5, 0.9, 3, 10.0);
	EXPECT_EQ(std::count(none.begin(), none.end(), TKeyFrameId(1)), 0);
}

TEST(SparseMap, AKeyFrameWithALoopEdgeIsNeverCulled)
{
	// Issue 28 item 3: culling ignored loop edges and the essential graph skips erased keyframes, so
	// a later pose graph silently lost the loop. The same five redundant views as above, kf2 closing
	// a loop with kf0: kf2 stays (ORB-SLAM2 marks loop keyframes not-to-erase), and so does its edge.
	std::mt19937 rng(4);
	CSparseMap map;
	sixViewsOfOneWall(map, rng);
	ASSERT_TRUE(map.addLoopEdge(2, 0));
	const auto erased = map.cullRedundantKeyFrames(5, 0.9, 3, 10.0);
	EXPECT_EQ(std::count(erased.begin(), erased.end(), TKeyFrameId(2)), 0) << "culled the loop keyframe";
	EXPECT_FALSE(erased.empty()) << "the other redundant keyframes still go";
	const auto graph = map.essentialGraph(100);
	EXPECT_TRUE(std::count(graph.begin(), graph.end(), std::make_pair(TKeyFrameId(0), TKeyFrameId(2))) == 1)
		<< "the loop edge is in the essential graph";
	expectGraphMatchesObservations(map);
}

TEST(SparseMap, AKeyFrameTheLoopStageHoldsIsNotCulledUntilReleased)
{
	// Issue 40 b: the loop's current keyframe could be culled between detection and correction
	// (local mapping goes on with the next keyframes meanwhile); correct() then moved nothing and the
	// loop still counted as closed. Pinned (as the system pins each keyframe queued for the loop
	// stage, and the matched one once found), kf1 and kf2 stay; released, they go as before.
	std::mt19937 rng(4);
	CSparseMap map;
	sixViewsOfOneWall(map, rng);
	ASSERT_TRUE(map.pinKeyFrame(1));
	ASSERT_TRUE(map.pinKeyFrame(2));
	ASSERT_TRUE(map.pinKeyFrame(2));  // two stages
	const auto held = map.cullRedundantKeyFrames(5, 0.9, 3, 10.0);
	EXPECT_EQ(std::count(held.begin(), held.end(), TKeyFrameId(1)), 0);
	EXPECT_EQ(std::count(held.begin(), held.end(), TKeyFrameId(2)), 0);
	EXPECT_FALSE(held.empty()) << "the others still go";
	map.unpinKeyFrame(1);
	map.unpinKeyFrame(2);
	const auto later = map.cullRedundantKeyFrames(5, 0.9, 3, 10.0);
	EXPECT_EQ(std::count(later.begin(), later.end(), TKeyFrameId(2)), 0) << "still held by one stage";
	map.unpinKeyFrame(2);
	for (const auto id : held) EXPECT_FALSE(map.pinKeyFrame(id)) << "a culled keyframe cannot be pinned";
	EXPECT_FALSE(map.pinKeyFrame(99));
	expectGraphMatchesObservations(map);
}

TEST(SparseMap, APinAStageOwnsIsUndoneHoweverTheStageEnds)
{
	// The loop stage (the current and the matched keyframe) and local mapping (a keyframe from its
	// insertion to the end of its own mapping) hold pins across work that may throw or return early;
	// a pin left behind keeps its keyframe from culling for the rest of the run. Each keyframe holds
	// one pin of another stage throughout, so that a pin undone twice shows (the count never goes
	// below zero).
	std::mt19937 rng(4);
	CSparseMap map;
	sixViewsOfOneWall(map, rng);
	for (TKeyFrameId id = 1; id <= 5; id++) ASSERT_TRUE(map.pinKeyFrame(id));
	const auto pins = [&](TKeyFrameId id) { return map.keyFrame(id).pinned; };
	{
		const CSparseMap::TPin p = map.pinned(1);
		ASSERT_TRUE(p);
		EXPECT_EQ(p.id(), 1u);
		EXPECT_EQ(pins(1), 2);
	}
	EXPECT_EQ(pins(1), 1) << "a scope's end";
	try
	{
		const CSparseMap::TPin p = map.pinned(2);
		throw std::runtime_error("the stage failed");
	}
	catch (const std::runtime_error&)
	{
	}
	EXPECT_EQ(pins(2), 1) << "an exception";
	// Handed on with the keyframe (queued for another stage), adopted there.
	{
		CSparseMap::TPin p = map.pinned(3);
		p.release();
	}
	EXPECT_EQ(pins(3), 2) << "a released pin is the next stage's";
	{
		const CSparseMap::TPin adopted = map.adoptPin(3);
	}
	EXPECT_EQ(pins(3), 1) << "the adopting stage undoes it";
	// Moved: one owner, one undo.
	{
		CSparseMap::TPin a = map.pinned(4);
		CSparseMap::TPin b = std::move(a);
		EXPECT_FALSE(a);
		EXPECT_TRUE(b);
		CSparseMap::TPin c = map.pinned(5);
		c = std::move(b);  // c's own pin (keyframe 5) is undone, keyframe 4's taken over
		EXPECT_EQ(pins(5), 1);
		EXPECT_EQ(pins(4), 2);
	}
	EXPECT_EQ(pins(4), 1);
	for (TKeyFrameId id = 1; id <= 5; id++) EXPECT_EQ(pins(id), 1) << "keyframe " << id;
	EXPECT_FALSE(map.pinned(99)) << "an unknown keyframe";
	for (TKeyFrameId id = 1; id <= 5; id++) map.unpinKeyFrame(id);
	// A keyframe added pinned (as the system adds one while the mapping stage may be culling) holds
	// its pin from the moment it is in the map, not from a second call a culling could precede.
	std::mt19937 rng2(9);
	{
		const CSparseMap::TPin added = map.addPinnedKeyFrame(
			observeWorld(6, mrpt::poses::CPose3D(0.035, 0, 0, 0, 0, 0), wall(80), range(0, 80), rng2, 0), 10.0);
		ASSERT_TRUE(added);
		EXPECT_EQ(added.id(), 6u);
		EXPECT_EQ(pins(6), 1);
		const auto culled = map.cullRedundantKeyFrames(5, 0.9, 3, 10.0);
		ASSERT_FALSE(culled.empty()) << "with the pins undone, culling goes on as before";
		EXPECT_EQ(std::count(culled.begin(), culled.end(), TKeyFrameId(6)), 0) << "the pinned new keyframe was culled";
		EXPECT_FALSE(map.pinned(culled.front())) << "a culled keyframe";
	}
	EXPECT_EQ(pins(6), 0);
}

TEST(SparseMap, RecentPointsListHoldsOnlyYoungPoints)
{
	std::mt19937 rng(5);
	CSparseMap map;
	addView(map, 0, {}, wall(50), std::vector<TPointId>(50, -1), rng);
	EXPECT_EQ(map.numRecentPoints(), 50u);
	// Each further keyframe sees kf0's points and creates 20 new ones elsewhere.
	for (std::size_t k = 1; k <= 4; k++)
	{
		auto world = wall(50);
		auto extra = wall(20, 3.5 + static_cast<double>(k));
		world.insert(world.end(), extra.begin(), extra.end());
		std::vector<TPointId> ids = range(0, 50);
		ids.resize(70, -1);
		addView(map, k, {}, world, ids, rng);
		map.cullRecentPoints(k, 0.25, 1);
	}
	// kf0's points left the list after three keyframes; the newest keyframes' are on it.
	EXPECT_LE(map.numRecentPoints(), 60u);
	EXPECT_GE(map.numRecentPoints(), 20u);
	// Grown-up points are not judged any more, however rarely tracking finds them.
	std::vector<TPointId> visible(100, 0);
	map.countTracking(visible, {});
	const std::size_t before = map.numPoints();
	map.cullRecentPoints(5, 0.25, 1);
	EXPECT_EQ(map.numPoints(), before);
	EXPECT_FALSE(map.point(0).bad);
}

TEST(SparseMap, BundleResultFromBeforeACorrectionIsRefused)
{
	std::mt19937 rng(6);
	const auto world = wall(40);
	CSparseMap map;
	addView(map, 0, {}, world, std::vector<TPointId>(40, -1), rng);
	addView(map, 1, mrpt::poses::CPose3D(0.1, 0, 0, 0, 0, 0), world, range(0, 40), rng);
	const TBundleWindow w = map.bundleWindow(1, 10, 10);
	ASSERT_EQ(w.keyFrames, std::vector<TKeyFrameId>{1});
	const mrpt::poses::CPose3D moved(0.5, 0, 0, 0, 0, 0);
	// A correction lands while the window is being optimised: the old result must not undo it.
	map.applyCorrection({{1, mrpt::poses::CPose3D(0.2, 0, 0, 0, 0, 0)}});
	EXPECT_EQ(map.generation(), 1u);
	EXPECT_FALSE(map.applyBundle(w, {{1, moved}}, w.positions, {}));
	EXPECT_NEAR(map.keyFramePose(1).x(), 0.2, 1e-12) << "the correction stands";
	// A window copied after the correction applies.
	const TBundleWindow w2 = map.bundleWindow(1, 10, 10);
	EXPECT_TRUE(map.applyBundle(w2, {{1, moved}}, w2.positions, {{3, 1}}));
	EXPECT_NEAR(map.keyFramePose(1).x(), 0.5, 1e-12);
	EXPECT_EQ(map.keyFrame(1).mapPoints[3], -1);
	expectGraphMatchesObservations(map);
}

TEST(SparseMap, KeyFramesAndPointsSerialiseAndRefuseCorruptData)
{
	std::mt19937 rng(7);
	const auto world = wall(30);
	CSparseMap map;
	auto f = observeWorld(0, mrpt::poses::CPose3D(0.1, -0.2, 0.3, 0.4, -0.1, 0.2), world, std::vector<TPointId>(30, -1),
						  rng, 2);
	TDetection d;
	d.classId = 0;
	d.score = 0.8f;
	d.box = {10, 20, 30, 40};
	d.dynamic = true;
	f->detections.push_back(d);
	map.addKeyFrame(f, 10.0);
	addView(map, 1, mrpt::poses::CPose3D(0.1, 0, 0, 0, 0, 0), world, range(0, 30), rng);
	const CKeyFrame kf = map.keyFrame(0);
	std::stringstream ss;
	kf.serialize(ss);
	const CKeyFrame back = CKeyFrame::deserialize(ss);
	EXPECT_EQ(back.id, kf.id);
	EXPECT_EQ(back.pose.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>(),
			  kf.pose.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>());
	EXPECT_EQ(back.mapPoints, kf.mapPoints);
	EXPECT_EQ(back.connections, kf.connections);
	EXPECT_EQ(back.orderedConnections, kf.orderedConnections);
	EXPECT_EQ(back.children, kf.children);
	ASSERT_EQ(back.size(), kf.size());
	EXPECT_EQ(cv::norm(back.features->descriptors, kf.features->descriptors, cv::NORM_HAMMING), 0);
	EXPECT_EQ(back.features->keypoints[7].pt, kf.features->keypoints[7].pt);
	EXPECT_EQ(back.features->keypoints[7].octave, 2);
	EXPECT_EQ(back.features->depth, kf.features->depth);
	ASSERT_EQ(back.detections.size(), 1u);
	EXPECT_EQ(back.detections[0].box, d.box);
	EXPECT_TRUE(back.detections[0].dynamic);

	const CMapPoint p = map.point(4);
	std::stringstream ps;
	p.serialize(ps);
	const CMapPoint pb = CMapPoint::deserialize(ps);
	EXPECT_EQ(pb.id, p.id);
	EXPECT_EQ(pb.position, p.position);
	EXPECT_EQ(pb.observations, p.observations);
	EXPECT_EQ(cv::norm(pb.descriptor, p.descriptor, cv::NORM_HAMMING), 0);

	// Truncated, and written by a newer format version: refused with a message, no crash.
	const std::string bytes = ss.str();
	std::stringstream cut;
	kf.serialize(cut);
	std::stringstream half(cut.str().substr(0, cut.str().size() / 2));
	EXPECT_THROW(CKeyFrame::deserialize(half), std::runtime_error);
	std::string future = ps.str();
	future[0] = 99;
	std::stringstream fs(future);
	try
	{
		CMapPoint::deserialize(fs);
		ADD_FAILURE() << "a newer version was accepted";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("version 99"), std::string::npos) << e.what();
	}
}

TEST(SparseMap, FusionAddsObservationsAndMergesDuplicates)
{
	std::mt19937 rng(8);
	const auto world = wall(40);
	CSparseMap map;
	addView(map, 0, {}, world, std::vector<TPointId>(40, -1), rng);  // points 0-39
	// kf1 matched nothing: it created duplicates 40-79 of the same places.
	addView(map, 1, mrpt::poses::CPose3D(0.05, 0, 0, 0, 0, 0), world, std::vector<TPointId>(40, -1), rng);
	ASSERT_EQ(map.numPoints(), 80u);
	EXPECT_EQ(map.keyFrame(0).weight(1), 0);
	// Points 0-19 found again at kf1's keypoints (which hold duplicates), points 50-59 in kf0.
	std::vector<TFuseCandidate> c;
	for (std::size_t j = 0; j < 20; j++) c.push_back({static_cast<TPointId>(j), 1, j});
	for (std::size_t j = 10; j < 20; j++)
		c.push_back({static_cast<TPointId>(40 + j), 0, j});  // already fused above: no-op
	EXPECT_EQ(map.fuse(c), 20u);
	EXPECT_EQ(map.numPoints(), 60u);
	EXPECT_EQ(map.keyFrame(0).weight(1), 20);
	for (std::size_t j = 0; j < 20; j++) EXPECT_EQ(map.keyFrame(1).mapPoints[j], map.keyFrame(0).mapPoints[j]);
	expectGraphMatchesObservations(map);
}

TEST(SparseMap, LocalKeyFramesFollowTheFramesMatchesNotTheNewestKeyFrame)
{
	// Place A: kf0 creates points 0-99, kf1 sees 0-79 and adds 100-119. Place B, seen from far
	// away: kf2 creates 120-219, kf3 sees 120-199 and adds 220-239. No point is shared between the places.
	std::mt19937 rng(7);
	const auto a = wall(100), b = wall(100, 6.0);
	CSparseMap map;
	std::vector<TPointId> none(100, -1), ids1(100, -1), ids3(100, -1);
	for (int j = 0; j < 80; j++) ids1[j] = j;
	for (int j = 0; j < 80; j++) ids3[j] = 120 + j;
	addView(map, 0, {}, a, none, rng);
	addView(map, 1, mrpt::poses::CPose3D(0.05, 0, 0, 0, 0, 0), a, ids1, rng);
	addView(map, 2, {}, b, none, rng);
	addView(map, 3, mrpt::poses::CPose3D(0.05, 0, 0, 0, 0, 0), b, ids3, rng);
	ASSERT_EQ(map.numPoints(), 240u);

	// A frame back at place A (the newest keyframe, kf3, is at B): the local map is place A's,
	// most shared first (a tie goes to the newer keyframe). kf2, sharing nothing, hangs under kf1
	// in the spanning tree and joins as its child (ORB-SLAM2 adds children and parent); kf3 does not.
	EXPECT_EQ(map.localKeyFrames(range(0, 50), 3, 10), (std::vector<TKeyFrameId>{1, 0, 2}));
	EXPECT_EQ(map.localKeyFrames(range(85, 100), 3, 10), (std::vector<TKeyFrameId>{0, 1}));
	// Only kf1 sees 100-119: kf0 joins as its covisible neighbour.
	EXPECT_EQ(map.localKeyFrames(range(100, 120), 3, 10), (std::vector<TKeyFrameId>{1, 0, 2}));
	EXPECT_EQ(map.localKeyFrames(range(100, 120), 3, 10, 0),
			  (std::vector<TKeyFrameId>{1, 2, 0}));  // no neighbours: child, parent
	// The cap holds; without seeds the fallback keyframe and its neighbours.
	EXPECT_EQ(map.localKeyFrames(range(0, 50), 3, 1), (std::vector<TKeyFrameId>{1}));
	EXPECT_EQ(map.localKeyFrames({}, 3, 10), (std::vector<TKeyFrameId>{3, 2}));
	// An erased fallback resolves to its good ancestor; erased keyframes never take part.
	map.eraseKeyFrame(3);
	EXPECT_EQ(map.localKeyFrames({}, 3, 10), (std::vector<TKeyFrameId>{2, 1}));
	EXPECT_EQ(map.localKeyFrames(range(120, 140), 3, 10), (std::vector<TKeyFrameId>{2, 1}));
	// The points of a local map: each once, only good ones.
	const TLocalMapPoints pts = map.pointsOfKeyFrames({0, 1});
	EXPECT_EQ(pts.ids.size(), 120u);
	EXPECT_EQ(pts.descriptors.rows, 120);
}

TEST(SparseMap, PointsSeenThroughInConsecutiveFramesAreErased)
{
	std::mt19937 rng(9);
	CSparseMap map;
	addView(map, 0, {}, wall(10), std::vector<TPointId>(10, -1), rng);
	const std::vector<TPointId> all = range(0, 10);
	// Point 0 is seen through three frames in a row: erased at the third. Point 1 twice, then found
	// (the count starts again), then twice more: kept. Point 2 never: kept.
	EXPECT_EQ(map.countTracking(all, {}, {0, 1}, 3), 0u);
	EXPECT_EQ(map.countTracking(all, {}, {0, 1}, 3), 0u);
	EXPECT_EQ(map.countTracking(all, {1}, {0}, 3), 1u);
	EXPECT_TRUE(map.point(0).bad);
	EXPECT_TRUE(map.point(0).observations.empty());
	EXPECT_EQ(map.countTracking(all, {}, {0, 1}, 3), 0u);  // a bad point is not erased twice
	EXPECT_EQ(map.countTracking(all, {}, {1}, 3), 0u);
	EXPECT_FALSE(map.point(1).bad);
	EXPECT_FALSE(map.point(2).bad);
	EXPECT_EQ(map.numPoints(), 9u);
	// 0 frames: the test is off.
	for (int k = 0; k < 5; k++) EXPECT_EQ(map.countTracking(all, {}, {2}, 0), 0u);
	EXPECT_FALSE(map.point(2).bad);
}

TEST(SparseMap, ErasedPointsAreForgottenAfterAFewKeyFramesSoStorageStaysBounded)
{
	// A long run in a known place erases about as many points as it makes; the map's storage must
	// follow its good points, not every point ever made (it did: 7x the live points after 3000
	// frames, and tracking's lookups slowed down as the run went on).
	std::mt19937 rng(4);
	const auto world = wall(40);
	CSparseMap map;
	addView(map, 0, {}, world, std::vector<TPointId>(40, -1), rng);  // points 0-39
	ASSERT_TRUE(map.erasePoint(3));
	std::vector<TPointId> ids(40, -1);
	for (int j = 10; j < 40; j++) ids[j] = j;
	addView(map, 1, mrpt::poses::CPose3D(0.02, 0, 0, 0, 0, 0), world, ids,
			rng);  // re-creates 0-9 (keypoints without a point)
	const TPointId duplicate = map.keyFrame(1).mapPoints[5];
	ASSERT_GE(duplicate, 40);
	ASSERT_TRUE(map.replacePoint(5, duplicate));
	// Still resolvable right after: erased reads as bad, fused follows to its replacement.
	EXPECT_TRUE(map.point(3).bad);
	EXPECT_EQ(map.point(5).replacedBy, duplicate);
	EXPECT_EQ(map.pointsById({5}).ids, std::vector<TPointId>{duplicate});
	const std::size_t stored = map.numStoredPoints();
	EXPECT_EQ(stored, map.numPoints() + 2);
	// Once three more keyframes are in, both are forgotten: storage = good points; a forgotten id reads as bad
	// without observations, a fused one resolves to nothing (its keypoints were moved long ago).
	for (std::size_t k = 2; k <= 5; k++)
		addView(map, k, mrpt::poses::CPose3D(0.02 * k, 0, 0, 0, 0, 0), world, ids, rng);
	EXPECT_EQ(map.numStoredPoints(), map.numPoints());
	EXPECT_TRUE(map.point(3).bad);
	EXPECT_TRUE(map.point(3).observations.empty());
	EXPECT_TRUE(map.point(5).bad);
	EXPECT_TRUE(map.pointsById({3, 5}).ids.empty());
	EXPECT_EQ(map.keyFrame(0).mapPoints[5], duplicate);
	EXPECT_THROW(map.point(1000000), std::out_of_range);  // never given
	expectGraphMatchesObservations(map);
}

TEST(SparseMap, CorrectionsMoveKeyFramesWithTheirPointsAndFollowTheSpanningTree)
{
	std::mt19937 rng(3);
	const auto world = wall(100);
	CSparseMap map;
	// kf0 creates points 0-99; kf1 (child of kf0) sees 0-59 and creates the rest anew; kf2 (child
	// of kf1) sees kf1's new points.
	std::vector<TPointId> none(100, -1), ids1(100, -1);
	for (int j = 0; j < 60; j++) ids1[j] = j;
	addView(map, 0, {}, world, none, rng);
	addView(map, 1, mrpt::poses::CPose3D(0.05, 0, 0, 0, 0, 0), world, ids1, rng);
	const CKeyFrame k1 = map.keyFrame(1);
	std::vector<TPointId> ids2(k1.mapPoints.begin(), k1.mapPoints.end());
	for (int j = 0; j < 60; j++) ids2[j] = -1;
	addView(map, 2, mrpt::poses::CPose3D(0.1, 0, 0, 0, 0, 0), world, ids2, rng);
	ASSERT_EQ(map.keyFrame(2).parent, std::optional<TKeyFrameId>(1));
	const TPointId made1 = k1.mapPoints[80], seen0 = 10;
	const auto before = map.point(made1).position, before0 = map.point(seen0).position;

	// correctKeyFrames: only kf1 moves (10 cm up), with the points it observes; kf2 stays.
	const auto g0 = map.generation();
	const mrpt::poses::CPose3D up(0, 0, 0.1, 0, 0, 0);
	map.correctKeyFrames({{1, up + map.keyFramePose(1)}});
	EXPECT_GT(map.generation(), g0);
	EXPECT_NEAR(map.keyFramePose(1).z(), 0.1, 1e-12);
	EXPECT_NEAR(map.keyFramePose(2).z(), 0.0, 1e-12);
	EXPECT_NEAR(map.point(made1).position.z, before.z + 0.1, 1e-9);
	EXPECT_NEAR(map.point(seen0).position.z, before0.z + 0.1, 1e-9);  // kf1 observes it too

	// applyCorrection: kf1 listed (back down), kf0 listed too (5 cm up), kf2 not: kf2 follows its
	// parent; kf1's points follow kf1; a point the group step moved with kf1 (seen0, made by kf0)
	// follows kf1 again, not its creator kf0 (issue 28 item 2: each point is corrected once, as
	// ORB-SLAM2's mnCorrectedByKF; it used to move with kf0 as well and end 5 cm above either).
	const auto kf0Before = map.point(20).position;  // made by kf0, seen by kf1 as well: moved in step 1
	map.applyCorrection({{1, mrpt::poses::CPose3D(0, 0, -0.1, 0, 0, 0) + map.keyFramePose(1)},
						 {0, mrpt::poses::CPose3D(0, 0, 0.05, 0, 0, 0) + map.keyFramePose(0)}});
	EXPECT_NEAR(map.keyFramePose(1).z(), 0.0, 1e-12);
	EXPECT_NEAR(map.keyFramePose(2).z(), -0.1, 1e-12);
	EXPECT_NEAR(map.point(made1).position.z, before.z, 1e-9);
	EXPECT_NEAR(map.point(seen0).position.z, before0.z, 1e-9) << "corrected twice";
	EXPECT_NEAR(map.point(20).position.z, kf0Before.z - 0.1, 1e-9);
	// A point only kf0 saw (made by kf0, 60-99 are kf1's own) moves with kf0.
	CSparseMap map2;
	std::mt19937 rng2(3);
	addView(map2, 0, {}, world, none, rng2);
	const auto p70 = map2.point(70).position;
	map2.applyCorrection({{0, mrpt::poses::CPose3D(0, 0, 0.05, 0, 0, 0) + map2.keyFramePose(0)}});
	EXPECT_NEAR(map2.point(70).position.z, p70.z + 0.05, 1e-9);
	map.applyCorrection(
		{{0, mrpt::poses::CPose3D(0, 0, -0.05, 0, 0, 0) + map.keyFramePose(0)}});  // undo kf0 for what follows

	// The essential graph holds the spanning tree and, once recorded, the loop edge.
	EXPECT_TRUE(map.addLoopEdge(2, 0));
	EXPECT_FALSE(map.addLoopEdge(2, 99));
	const auto edges = map.essentialGraph(1000);
	for (const auto& e : {std::make_pair<TKeyFrameId, TKeyFrameId>(0, 1), {1, 2}, {0, 2}})
		EXPECT_NE(std::find(edges.begin(), edges.end(), e), edges.end()) << e.first << "-" << e.second;
	EXPECT_EQ(edges.size(), 3u);

	// A global BA result copied before a correction is refused; one copied after is written, and a
	// keyframe added meanwhile follows its ancestor.
	const TBundleWindow stale = map.globalBundleWindow();
	map.applyCorrection({});
	EXPECT_FALSE(map.applyGlobalBundle(stale, stale.poses, stale.positions, {}));
	TBundleWindow w = map.globalBundleWindow();
	EXPECT_EQ(w.fixedKeyFrames, std::vector<TKeyFrameId>{0});
	EXPECT_EQ(w.points.size(), map.numPoints());
	std::vector<TPointId> ids3(100, -1);
	addView(map, 3, mrpt::poses::CPose3D(0.1, 0, -0.1, 0, 0, 0), world, ids3, rng);
	auto poses = w.poses;
	for (auto& [k, p] : poses)
		if (k != 0) p = mrpt::poses::CPose3D(0.2, 0, 0, 0, 0, 0) + p;
	const double z3 = map.keyFramePose(3).x();
	EXPECT_TRUE(map.applyGlobalBundle(w, poses, w.positions, {}));
	EXPECT_NEAR(map.keyFramePose(3).x(), z3 + 0.2, 1e-9);
	expectGraphMatchesObservations(map);
}

namespace
{
// A map body as CSparseMap::serialize writes it, from copies of `map`'s keyframes and points that
// `edit` may damage first.
std::string mapBody(const CSparseMap& map,
					const std::function<void(std::vector<CKeyFrame>&, std::vector<CMapPoint>&)>& edit,
					std::uint64_t nextKf = 0, std::int64_t nextPt = 0)
{
	std::vector<CKeyFrame> kfs;
	for (const auto& k : map.keyFramePoses()) kfs.push_back(map.keyFrame(k.id));
	std::vector<CMapPoint> pts = map.points();
	std::sort(pts.begin(), pts.end(), [](const CMapPoint& a, const CMapPoint& b) { return a.id < b.id; });
	edit(kfs, pts);
	std::ostringstream o(std::ios::binary);
	binio::put<std::uint32_t>(o, CSparseMap::kSerialVersion);
	binio::put<std::uint64_t>(o, nextKf ? nextKf : kfs.back().id + 1);
	binio::put<std::int64_t>(o, nextPt ? nextPt : pts.back().id + 1);
	binio::put<std::uint64_t>(o, 0);
	binio::put<std::uint64_t>(o, kfs.size());
	for (const auto& k : kfs) k.serialize(o);
	binio::put<std::uint64_t>(o, pts.size());
	for (const auto& p : pts) p.serialize(o);
	return std::move(o).str();
}

// Two keyframes 10 cm apart (the second turned by `yaw`) seeing the 30 points of a wall.
void twoViews(CSparseMap& map, std::mt19937& rng, double yaw = 0)
{
	const auto world = wall(30);
	addView(map, 0, mrpt::poses::CPose3D(), world, std::vector<TPointId>(30, -1), rng);
	addView(map, 1, mrpt::poses::CPose3D(0.1, 0, 0, yaw, 0, 0), world, range(0, 30), rng);
}
}  // namespace

TEST(SparseMap, AMapFileWhoseContentDisagreesWithItselfIsRefusedAndTheMapKept)
{
	// Issue 28 item 4: content behind a valid checksum that the matcher or tracking would trip on.
	std::mt19937 rng(3);
	const auto world = wall(30);
	CSparseMap map;
	twoViews(map, rng);
	const auto loads = [](const std::string& body)
	{
		CSparseMap m;
		std::istringstream in(body, std::ios::binary);
		m.deserialize(in);
		return m.numKeyFrames();
	};
	ASSERT_EQ(loads(mapBody(map, [](auto&, auto&) {})), 2u) << "the undamaged copy loads";
	const auto refused = [&](const char* what, const std::string& body, const std::string& fragment)
	{
		CSparseMap m;
		addView(m, 0, mrpt::poses::CPose3D(), world, std::vector<TPointId>(30, -1), rng);
		std::istringstream in(body, std::ios::binary);
		try
		{
			m.deserialize(in);
			ADD_FAILURE() << what << ": accepted";
		}
		catch (const std::runtime_error& e)
		{
			EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << what << ": " << e.what();
		}
		EXPECT_EQ(m.numKeyFrames(), 1u) << what << ": the map in place is kept";
	};
	// An empty point descriptor shifted every later row in the matcher; a 16-byte one threw in tracking.
	refused("empty descriptor", mapBody(map, [](auto&, auto& p) { p[3].descriptor = cv::Mat(); }),
			"descriptor of 0 bytes");
	refused("short descriptor",
			mapBody(map, [](auto&, auto& p) { p[3].descriptor = p[3].descriptor.colRange(0, 16).clone(); }),
			"descriptor of 16 bytes");
	// Intrinsics that projection divides by.
	refused("zero fx", mapBody(map, [](auto& k, auto&) { k[1].camera.fx(0); }), "intrinsics");
	refused("NaN cy", mapBody(map, [](auto& k, auto&) { k[0].camera.cy(std::nan("")); }), "intrinsics");
	// The spanning tree one way only.
	refused("child without parent", mapBody(map, [](auto& k, auto&) { k[1].parent.reset(); }),
			"child unknown or with another parent");
	refused("parent without child", mapBody(map, [](auto& k, auto&) { k[0].children.clear(); }),
			"does not list it as a child");
	// A keyframe naming a point that does not observe it back.
	refused("one-way observation", mapBody(map, [](auto&, auto& p) { p[5].observations.erase(1); }),
			"not observed back");
	// Issue 40 (g): covisibility weights the observations do not back are recounted, not trusted:
	// a weight of 500 on 30 shared points, a connection to the first keyframe dropped.
	{
		CSparseMap m;
		std::istringstream in(mapBody(map,
									  [](auto& k, auto&)
									  {
										  k[1].connections[0] = 500;
										  k[0].connections.clear();
										  k[0].orderedConnections.clear();
									  }),
							  std::ios::binary);
		m.deserialize(in);
		EXPECT_EQ(m.keyFrame(1).weight(0), 30);
		EXPECT_EQ(m.keyFrame(0).weight(1), 30);
		EXPECT_EQ(m.covisible(0, 5), (std::vector<TKeyFrameId>{1}));
		expectGraphMatchesObservations(m);
	}
	// Id counters that would overflow.
	refused("point counter",
			mapBody(
				map, [](auto&, auto&) {}, 0, std::int64_t(1) << 62),
			"id counter out of range");

	// A file whose map is sound but whose octree section is not: refused, and the map in place is
	// kept (it was replaced before the octree was read).
	TempDir d("map_bad_octree");
	std::string file("YESSLAMM", 8);
	const std::uint32_t version = 1;  // a version 1 file (no export frame after the octree) is still read
	const std::uint64_t vocabulary = 0, length = 40;
	file.append(reinterpret_cast<const char*>(&version), 4);
	file.append(reinterpret_cast<const char*>(&vocabulary), 8);
	file += mapBody(map, [](auto&, auto&) {});
	const double threshold = 0.5;
	file.append(reinterpret_cast<const char*>(&threshold), 8);
	file.append(reinterpret_cast<const char*>(&length), 8);
	file += std::string(length, 'x');
	const std::uint64_t sum = binio::checksum(file.data(), file.size());
	file.append(reinterpret_cast<const char*>(&sum), 8);
	writeText(d / "bad_octree.ysm", file);
	CSparseMap inPlace;
	addView(inPlace, 0, mrpt::poses::CPose3D(), world, std::vector<TPointId>(30, -1), rng);
	expectInputError([&] { loadMapFile(d / "bad_octree.ysm", inPlace, 0); }, {"bad_octree.ysm", "inconsistent"});
	EXPECT_EQ(inPlace.numKeyFrames(), 1u);
	// The same map with an empty octree section loads and replaces it.
	std::string plainFile = file.substr(0, file.size() - 8 - 16 - length) + std::string(16, '\0');
	const std::uint64_t sum2 = binio::checksum(plainFile.data(), plainFile.size());
	plainFile.append(reinterpret_cast<const char*>(&sum2), 8);
	writeText(d / "good.ysm", plainFile);
	const TMapFileInfo info = loadMapFile(d / "good.ysm", inPlace, 0);
	EXPECT_EQ(inPlace.numKeyFrames(), 2u);
	// Its octree was built in the map's own frame: exports stay there.
	EXPECT_EQ(info.worldFrame.kind, TWorldFrame::EKind::Optical);
	EXPECT_EQ(info.worldFrame.worldFromMap, mrpt::poses::CPose3D());
}

TEST(SparseMap, AMapFileKeepsItsExportFrameExactlyAndRefusesABrokenOne)
{
	// Issue 30 item 4: the frame the map's octree was built in (and a later run exports in) is
	// saved with it, bit for bit, so that a map saved again keeps its bytes.
	std::mt19937 rng(8);
	CSparseMap map;
	twoViews(map, rng, 0.05);
	TempDir d("map_frame");
	TWorldFrame f;
	f.kind = TWorldFrame::EKind::ZUp;
	f.floorSeen = true;
	f.cameraHeight = 1.234;
	f.worldFromMap =
		mrpt::poses::CPose3D(0.1, -0.2, 1.234, mrpt::DEG2RAD(-91.0), mrpt::DEG2RAD(2.0), mrpt::DEG2RAD(-95.0));
	saveMapFile(d / "a.ysm", map, 0, nullptr, f);
	CSparseMap back;
	const TMapFileInfo info = loadMapFile(d / "a.ysm", back, 0);
	EXPECT_EQ(info.version, kMapFileVersion);
	EXPECT_EQ(info.worldFrame.kind, TWorldFrame::EKind::ZUp);
	EXPECT_TRUE(info.worldFrame.floorSeen);
	EXPECT_EQ(info.worldFrame.cameraHeight, 1.234);
	EXPECT_EQ(info.worldFrame.worldFromMap.getRotationMatrix(), f.worldFromMap.getRotationMatrix());
	EXPECT_EQ(info.worldFrame.worldFromMap.asVectorVal().head<3>(), f.worldFromMap.asVectorVal().head<3>());
	saveMapFile(d / "b.ysm", back, 0, nullptr, info.worldFrame);
	EXPECT_EQ(readText(d / "a.ysm"), readText(d / "b.ysm"));
	// A frame whose rotation is no rotation (a scaled matrix) is refused, checksum and all right.
	std::string bytes = readText(d / "a.ysm");
	const std::size_t r00 =
		bytes.size() - 8 - 12 * 8;  // the rotation's first entry, before the translation and the checksum
	double v;
	std::memcpy(&v, bytes.data() + r00, 8);
	v *= 1.5;
	std::memcpy(bytes.data() + r00, &v, 8);
	bytes.resize(bytes.size() - 8);
	const std::uint64_t sum = binio::checksum(bytes.data(), bytes.size());
	bytes.append(reinterpret_cast<const char*>(&sum), 8);
	writeText(d / "bad.ysm", bytes);
	expectInputError([&] { loadMapFile(d / "bad.ysm", back, 0); }, {"bad.ysm", "not a rotation"});
}

TEST(SparseMap, ManyCorrectionsKeepEveryKeyFramesRotationARotation)
{
	// A correction writes T_new from T_old by composition; with T_old's rotation off orthonormal
	// by e, the delta T_new T_old^-1 applied to T_old left it off by 3e, so the first keyframe
	// (never re-estimated by BA) ended in garbage after some thirty loop corrections (found by
	// System.ACorrectionBetweenTrackingAndADelayedKeyFrameCarriesOverToIt: NaN poses).
	std::mt19937 rng(5);
	CSparseMap map;
	twoViews(map, rng, 0.05);
	const mrpt::poses::CPose3D T(0.03, -0.01, 0.02, mrpt::DEG2RAD(1.0), mrpt::DEG2RAD(-0.5), 0);
	mrpt::poses::CPose3D expected;
	for (int n = 0; n < 80; n++)
	{
		std::map<TKeyFrameId, mrpt::poses::CPose3D> poses;
		for (const auto& k : map.keyFramePoses()) poses[k.id] = T + k.pose;
		map.applyCorrection(poses);
		expected = T + expected;
	}
	const Eigen::Matrix3d R = map.keyFramePose(0).getRotationMatrix().asEigen();
	EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-9);
	EXPECT_LT((map.keyFramePose(0).asVectorVal() - expected.asVectorVal()).norm(), 1e-6);
	// The keyframes stay where they were relative to each other.
	EXPECT_NEAR((map.keyFramePose(1) - map.keyFramePose(0)).asVectorVal().head<3>().norm(), 0.1, 1e-6);
}

TEST(SparseMap, APointCarriesHowItHasBeenSeen)
{
	// Issue 27 (ORB-SLAM2's MapPoint::UpdateNormalAndDepth, for the tracker's view checks): a point
	// made by keyframe 0 (from 2 m, at pyramid level 1) and then seen by three keyframes to its
	// left; one of them is erased.
	std::mt19937 rng(7);
	const std::vector<mrpt::math::TPoint3D> world{{0, 0, 2}};
	CSparseMap map;
	map.addKeyFrame(observeWorld(0, mrpt::poses::CPose3D(), world, {-1}, rng, 1), 10.0);
	for (std::size_t k = 1; k <= 3; k++)
		map.addKeyFrame(
			observeWorld(k, mrpt::poses::CPose3D(-0.5 * static_cast<double>(k), 0, 0, 0, 0, 0), world, {0}, rng, 0),
			10.0);
	// The mean of the unit directions from the keyframes to it, and its distance and level in the
	// keyframe that made it; as the observations are now, so without the erased keyframe.
	const auto expectViews = [&](const std::vector<int>& keyFrames)
	{
		const TLocalMapPoints pts = map.pointsOfKeyFrames({0});
		ASSERT_TRUE(pts.hasViews());
		Eigen::Vector3d n(0, 0, 0);
		for (int k : keyFrames) n += Eigen::Vector3d(0.5 * k, 0, 2).normalized();
		n.normalize();
		EXPECT_NEAR(pts.normals[0].x, n.x(), 1e-6);
		EXPECT_NEAR(pts.normals[0].y, 0.0, 1e-6);
		EXPECT_NEAR(pts.normals[0].z, n.z(), 1e-6);
		EXPECT_NEAR(pts.refDistances[0], 2.0, 1e-5);
		EXPECT_EQ(pts.refOctaves[0], 1);
	};
	expectViews({0, 1, 2, 3});
	ASSERT_TRUE(map.eraseKeyFrame(3));
	expectViews({0, 1, 2});
	// Points from the map by id carry them too; the tracker's own frame points do not.
	EXPECT_TRUE(map.pointsById({0}).hasViews());
}
