// Hamming matching: the distance, projection-guided search and brute force with the ratio test.
#include <gtest/gtest.h>

#include <random>

#include "mrpt_yesslam/feature/COrbMatcher.h"

using namespace mrpt_yesslam;

namespace
{
cv::Mat randomDescriptors(int n, std::mt19937& rng)
{
	cv::Mat d(n, 32, CV_8U);
	cv::randu(d, 0, 256);
	std::uniform_int_distribution<int> b(0, 255);
	for (int i = 0; i < n; i++)
		for (int j = 0; j < 32; j++) d.at<uchar>(i, j) = static_cast<uchar>(b(rng));
	return d;
}

// Flips `bits` bits of a descriptor row.
cv::Mat flip(const cv::Mat& row, int bits)
{
	cv::Mat r = row.clone();
	for (int k = 0; k < bits; k++) r.at<uchar>(0, k % 32) ^= static_cast<uchar>(1u << (k / 32));
	return r;
}

TFrame frameWith(const std::vector<cv::Point2f>& pts, const cv::Mat& desc)
{
	TFrame f;
	f.camera.ncols = 640;
	f.camera.nrows = 480;
	f.camera.fx(500);
	f.camera.fy(500);
	f.camera.cx(320);
	f.camera.cy(240);
	for (const auto& p : pts)
	{
		f.features.keypoints.emplace_back(p, 31.f, -1.f, 0.f, 0);
		f.features.depth.push_back(2.0f);
		f.features.dynamic.push_back(false);
	}
	f.features.descriptors = desc.clone();
	f.mapPoints.assign(pts.size(), -1);
	return f;
}
}  // namespace

TEST(OrbMatcher, HammingDistanceEqualsOpenCv)
{
	std::mt19937 rng(1);
	const cv::Mat d = randomDescriptors(50, rng);
	for (int i = 0; i + 1 < d.rows; i++)
		EXPECT_EQ(orbDistance(d.ptr<uchar>(i), d.ptr<uchar>(i + 1)),
				  static_cast<int>(cv::norm(d.row(i), d.row(i + 1), cv::NORM_HAMMING)));
}

TEST(OrbMatcher, ProjectionSearchFindsTheKeypointAtTheProjection)
{
	std::mt19937 rng(2);
	const cv::Mat pointDesc = randomDescriptors(3, rng);
	// Points at x = -0.4, 0, 0.4 m, 2 m ahead: pixels 220, 320, 420 on row 240 (identity pose).
	TLocalMapPoints pts;
	for (int j = 0; j < 3; j++)
	{
		pts.ids.push_back(100 + j);
		pts.positions.push_back({-0.4 + 0.4 * j, 0.0, 2.0});
	}
	pts.descriptors = pointDesc;
	// Keypoints: near each projection (2 px off) with a slightly changed descriptor, plus a decoy
	// with an unrelated descriptor right at the middle projection and one far away with a perfect one.
	cv::Mat desc;
	desc.push_back(flip(pointDesc.row(0), 10));
	desc.push_back(flip(pointDesc.row(1), 12));
	desc.push_back(flip(pointDesc.row(2), 8));
	desc.push_back(randomDescriptors(1, rng));
	desc.push_back(pointDesc.row(2).clone());
	TFrame f = frameWith({{222, 241}, {318, 240}, {420, 238}, {320, 240}, {600, 50}}, desc);
	const COrbMatcher m(100, 0.9);
	std::vector<std::size_t> inView;
	auto found = m.searchByProjection(f, mrpt::poses::CPose3D(), pts, 8.0, &inView);
	ASSERT_EQ(found.size(), 3u);
	EXPECT_EQ(inView.size(), 3u);
	std::sort(found.begin(), found.end(), [](const TMatch& a, const TMatch& b) { return a.point < b.point; });
	for (std::size_t j = 0; j < 3; j++) EXPECT_EQ(found[j].keypoint, j);
	// A dynamic keypoint is never matched (eq. 3), and a point behind the camera is not in view.
	f.features.dynamic[1] = true;
	pts.positions[2].z = -2.0;
	found = m.searchByProjection(f, mrpt::poses::CPose3D(), pts, 8.0, &inView);
	EXPECT_EQ(inView.size(), 2u);
	for (const auto& x : found) EXPECT_NE(x.keypoint, 1u);
	// The wrong pose puts the projections 100 px off: nothing within the radius.
	EXPECT_TRUE(m.searchByProjection(f, mrpt::poses::CPose3D(0.4, 0, 0, 0, 0, 0), pts, 8.0).empty());
}

TEST(OrbMatcher, ViewChecksSearchAPointOnlyWhereItsPyramidAndItsViewsReach)
{
	// Issue 27 (ORB-SLAM2's map-point normal and scale-invariance distances): four points 2 m ahead
	// of a camera at the origin, each with a keypoint at its projection carrying its descriptor.
	std::mt19937 rng(4);
	const cv::Mat pointDesc = randomDescriptors(4, rng);
	TLocalMapPoints pts;
	const auto add = [&](TPointId id, mrpt::math::TPoint3D P, mrpt::math::TPoint3D n, float refDistance)
	{
		pts.ids.push_back(id);
		pts.positions.push_back(P);
		pts.normals.push_back(n * (1.0 / n.norm()));
		pts.refDistances.push_back(refDistance);
		pts.refOctaves.push_back(0);
	};
	add(0, {0, 0, 2}, {0, 0, 1}, 2.0f);       // seen from here before: level 0
	add(1, {0.4, 0, 2}, {-1, 0, 0.2}, 2.0f);  // only ever seen from its side, 80 degrees off
	add(2, {-0.4, 0, 2}, {0, 0, 1}, 0.5f);    // seen from 0.5 m at level 0: past its pyramid's reach at 2 m
	add(3, {0, 0.4, 2}, {0, 0, 1}, 4.0f);     // seen from 4 m at level 0: at 2 m it is at level 4
	pts.descriptors = pointDesc;
	cv::Mat desc;
	for (int j = 0; j < 4; j++) desc.push_back(pointDesc.row(j).clone());
	desc.push_back(flip(pointDesc.row(3), 10));  // point 3 again, at the level its distance predicts
	desc.push_back(randomDescriptors(1, rng));   // far off, at the coarsest level (the pyramid's reach)
	TFrame f = frameWith({{320, 240}, {420, 240}, {220, 240}, {320, 340}, {322, 342}, {600, 50}}, desc);
	f.features.keypoints[4].octave = 4;
	f.features.keypoints[5].octave = 7;
	const COrbMatcher m(100, 0.9);
	const auto byPoint = [](std::vector<TMatch> v)
	{
		std::sort(v.begin(), v.end(), [](const TMatch& a, const TMatch& b) { return a.point < b.point; });
		return v;
	};
	std::vector<std::size_t> inView;
	// Without the checks every point is in view and takes the keypoint with its own descriptor.
	auto found = byPoint(m.searchByProjection(f, mrpt::poses::CPose3D(), pts, 4.0, &inView, false, 1.2, false));
	EXPECT_EQ(inView.size(), 4u);
	ASSERT_EQ(found.size(), 4u);
	for (std::size_t j = 0; j < 4; j++) EXPECT_EQ(found[j].keypoint, j);
	// With them: the point seen only from its side and the one past its pyramid's reach are not in
	// view; point 3 is searched at level 4 (and 3), where its keypoint of level 0 is not.
	found = byPoint(m.searchByProjection(f, mrpt::poses::CPose3D(), pts, 4.0, &inView, false, 1.2, true));
	EXPECT_EQ(inView, (std::vector<std::size_t>{0, 3}));
	ASSERT_EQ(found.size(), 2u);
	EXPECT_EQ(found[0].keypoint, 0u);
	EXPECT_EQ(found[1].point, 3u);
	EXPECT_EQ(found[1].keypoint, 4u);
	// Issue 40 (f): the pyramid's reach is the extractor's levels, not the frame's coarsest
	// keypoint. Without the keypoints of levels 4 and 7 the frame still searched 8 levels: point 3,
	// at level 4 from here, is in view (its keypoint of level 0 is not its match).
	TFrame fine = f;
	fine.features.keypoints[4].octave = 0;
	fine.features.keypoints[5].octave = 0;
	fine.features.levels = 8;
	EXPECT_TRUE(m.searchByProjection(fine, mrpt::poses::CPose3D(), pts, 4.0, &inView, false, 1.2, true).size() == 1u);
	EXPECT_EQ(inView, (std::vector<std::size_t>{0, 3}));
	// Features of unknown origin: the highest keypoint level stands for the pyramid.
	fine.features.levels = 0;
	m.searchByProjection(fine, mrpt::poses::CPose3D(), pts, 4.0, &inView, false, 1.2, true);
	EXPECT_EQ(inView, (std::vector<std::size_t>{0}));
	// Points without views (made from a frame) are searched as before.
	pts.normals.clear();
	EXPECT_EQ(m.searchByProjection(f, mrpt::poses::CPose3D(), pts, 4.0, &inView, false, 1.2, true).size(), 4u);
}

TEST(OrbMatcher, BruteForceRatioTestRejectsAmbiguousMatches)
{
	std::mt19937 rng(3);
	const cv::Mat pointDesc = randomDescriptors(40, rng);
	cv::Mat desc;
	for (int j = 0; j < 40; j++) desc.push_back(flip(pointDesc.row(j), 6));
	std::vector<cv::Point2f> px(40, {100, 100});
	TFrame f = frameWith(px, desc);
	const COrbMatcher m(100, 0.8);
	auto found = m.matchBruteForce(f, pointDesc);
	ASSERT_EQ(found.size(), 40u);
	for (const auto& x : found) EXPECT_EQ(x.keypoint, x.point);
	// Two points with the same descriptor: the keypoint that matches both is ambiguous.
	cv::Mat twins = pointDesc.clone();
	pointDesc.row(5).copyTo(twins.row(6));
	found = m.matchBruteForce(f, twins);
	for (const auto& x : found) EXPECT_NE(x.keypoint, 5u);
	EXPECT_EQ(found.size(), 38u);  // keypoints 5 (ambiguous) and 6 (its point is gone) unmatched
}
