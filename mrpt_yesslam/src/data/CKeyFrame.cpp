#include "mrpt_yesslam/data/CKeyFrame.h"

#include <cmath>

#include <algorithm>
#include <stdexcept>

#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "mrpt_yesslam/util/BinaryIO.h"

namespace mrpt_yesslam
{
cv::Point3d CKeyFrame::backProject(std::size_t i) const
{
	const auto& p = features->keypoints[i].pt;
	return CPinholeCamera(camera).backProject(p.x, p.y, features->depth[i]);
}

namespace
{
// A keypoint as stored: position, size, angle, response and octave (class_id is not used).
struct TStoredKeyPoint
{
	float x, y, size, angle, response;
	std::int32_t octave;
};

// Poses as their 3x4 matrix, so that a saved and reloaded pose is bit-identical (yaw/pitch/roll
// would round).
void putPose(std::ostream& o, const mrpt::poses::CPose3D& p)
{
	const auto M = p.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>();
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 4; c++) binio::put(o, M(r, c));
}

mrpt::poses::CPose3D getPose(std::istream& i, const char* what)
{
	mrpt::math::CMatrixDouble44 M = mrpt::math::CMatrixDouble44::Identity();
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 4; c++) M(r, c) = binio::get<double>(i, what);
	return mrpt::poses::CPose3D(M);
}
}  // namespace

void CKeyFrame::serialize(std::ostream& o) const
{
	using namespace binio;
	put<std::uint32_t>(o, kSerialVersion);
	put<std::uint64_t>(o, id);
	put<std::uint64_t>(o, frameId);
	put(o, timestamp);
	put<std::uint32_t>(o, camera.ncols);
	put<std::uint32_t>(o, camera.nrows);
	for (double v : {camera.fx(), camera.fy(), camera.cx(), camera.cy()}) put(o, v);
	for (int k = 0; k < 5; k++) put(o, camera.dist[k]);
	std::vector<TStoredKeyPoint> kps;
	std::vector<float> depth;
	std::vector<std::uint8_t> dyn, desc;
	if (features)
	{
		for (const auto& k : features->keypoints)
			kps.push_back({k.pt.x, k.pt.y, k.size, k.angle, k.response, k.octave});
		depth = features->depth;
		dyn.assign(features->dynamic.begin(), features->dynamic.end());
		const cv::Mat d = features->descriptors.isContinuous() ? features->descriptors : features->descriptors.clone();
		if (!d.empty()) desc.assign(d.ptr<std::uint8_t>(0), d.ptr<std::uint8_t>(0) + d.total() * d.elemSize());
	}
	putVector(o, kps);
	putVector(o, depth);
	putVector(o, dyn);
	putVector(o, desc);
	std::vector<std::uint8_t> bgr;
	for (const auto& c : colors) bgr.insert(bgr.end(), {c[0], c[1], c[2]});
	putVector(o, bgr);
	std::vector<float> dets;
	for (const auto& d : detections)
	{
		dets.insert(dets.end(), {static_cast<float>(d.classId), d.score, d.box.x, d.box.y, d.box.width, d.box.height,
								 static_cast<float>(d.instanceId), d.dynamic ? 1.f : 0.f});
	}
	putVector(o, dets);
	putPose(o, pose);
	putVector(o, std::vector<std::int64_t>(mapPoints.begin(), mapPoints.end()));
	put<std::uint8_t>(o, bad);
	std::vector<std::int64_t> conn;
	for (const auto& [k, w] : connections)
	{
		conn.push_back(static_cast<std::int64_t>(k));
		conn.push_back(w);
	}
	putVector(o, conn);
	put<std::int64_t>(o, parent ? static_cast<std::int64_t>(*parent) : -1);
	putVector(o, std::vector<std::uint64_t>(children.begin(), children.end()));
	putPose(o, poseInParent);
	putVector(o, std::vector<std::uint64_t>(loopEdges.begin(), loopEdges.end()));
}

CKeyFrame CKeyFrame::deserialize(std::istream& i)
{
	using namespace binio;
	const std::uint32_t version = getVersion(i, "keyframe", kSerialVersion);
	CKeyFrame kf;
	kf.id = get<std::uint64_t>(i, "keyframe id");
	kf.frameId = get<std::uint64_t>(i, "keyframe frame id");
	kf.timestamp = get<double>(i, "keyframe timestamp");
	kf.camera.ncols = get<std::uint32_t>(i, "keyframe camera");
	kf.camera.nrows = get<std::uint32_t>(i, "keyframe camera");
	kf.camera.fx(get<double>(i, "keyframe camera"));
	kf.camera.fy(get<double>(i, "keyframe camera"));
	kf.camera.cx(get<double>(i, "keyframe camera"));
	kf.camera.cy(get<double>(i, "keyframe camera"));
	for (int k = 0; k < 5; k++) kf.camera.dist[k] = get<double>(i, "keyframe camera");
	// Projection divides by fx, fy and sizes grids by the image: a map with other values would give
	// NaN poses or empty grids far from where it was read.
	const auto& K = kf.camera;
	bool intrinsicsOk = K.ncols > 0 && K.nrows > 0 && K.ncols <= 100000 && K.nrows <= 100000 && std::isfinite(K.fx()) &&
						std::isfinite(K.fy()) && K.fx() > 0 && K.fy() > 0 && std::isfinite(K.cx()) &&
						std::isfinite(K.cy());
	for (int k = 0; k < 5; k++) intrinsicsOk = intrinsicsOk && std::isfinite(K.dist[k]);
	if (!intrinsicsOk) throw std::runtime_error("keyframe camera intrinsics not finite and positive");
	auto f = std::make_shared<TFeatures>();
	for (const auto& k : getVector<TStoredKeyPoint>(i, "keyframe keypoints"))
	{
		cv::KeyPoint kp({k.x, k.y}, k.size, k.angle, k.response, k.octave);
		f->keypoints.push_back(kp);
	}
	f->depth = getVector<float>(i, "keyframe depth");
	const auto dyn = getVector<std::uint8_t>(i, "keyframe dynamic flags");
	f->dynamic.assign(dyn.begin(), dyn.end());
	const auto desc = getVector<std::uint8_t>(i, "keyframe descriptors");
	const std::size_t n = f->keypoints.size();
	if (f->depth.size() != n || f->dynamic.size() != n || desc.size() != 32 * n)
		throw std::runtime_error("keyframe feature arrays of different lengths");
	f->descriptors = n ? cv::Mat(static_cast<int>(n), 32, CV_8U, const_cast<std::uint8_t*>(desc.data())).clone()
					   : cv::Mat(0, 32, CV_8U);
	kf.features = f;
	const auto bgr = getVector<std::uint8_t>(i, "keyframe colours");
	if (bgr.size() % 3) throw std::runtime_error("keyframe colour list of wrong length");
	for (std::size_t k = 0; k < bgr.size(); k += 3) kf.colors.emplace_back(bgr[k], bgr[k + 1], bgr[k + 2]);
	const auto dets = getVector<float>(i, "keyframe detections");
	if (dets.size() % 8) throw std::runtime_error("keyframe detection list of wrong length");
	for (std::size_t k = 0; k < dets.size(); k += 8)
	{
		TDetection d;
		d.classId = static_cast<int>(dets[k]);
		d.score = dets[k + 1];
		d.box = {dets[k + 2], dets[k + 3], dets[k + 4], dets[k + 5]};
		d.instanceId = static_cast<int>(dets[k + 6]);
		d.dynamic = dets[k + 7] != 0;
		kf.detections.push_back(d);
	}
	kf.pose = getPose(i, "keyframe pose");
	const auto mp = getVector<std::int64_t>(i, "keyframe map points");
	kf.mapPoints.assign(mp.begin(), mp.end());
	if (kf.mapPoints.size() != n) throw std::runtime_error("keyframe map point list of wrong length");
	kf.bad = get<std::uint8_t>(i, "keyframe flags") != 0;
	const auto conn = getVector<std::int64_t>(i, "keyframe connections");
	if (conn.size() % 2) throw std::runtime_error("odd connection list reading keyframe");
	for (std::size_t k = 0; k < conn.size(); k += 2)
	{
		kf.connections[static_cast<TKeyFrameId>(conn[k])] = static_cast<int>(conn[k + 1]);
		kf.orderedConnections.push_back(static_cast<TKeyFrameId>(conn[k]));
	}
	std::stable_sort(kf.orderedConnections.begin(), kf.orderedConnections.end(),
					 [&](TKeyFrameId a, TKeyFrameId b) { return kf.connections[a] > kf.connections[b]; });
	const auto parent = get<std::int64_t>(i, "keyframe parent");
	if (parent >= 0) kf.parent = static_cast<TKeyFrameId>(parent);
	for (auto c : getVector<std::uint64_t>(i, "keyframe children")) kf.children.insert(c);
	kf.poseInParent = getPose(i, "keyframe pose in parent");
	if (version >= 2)
		for (auto e : getVector<std::uint64_t>(i, "keyframe loop edges")) kf.loopEdges.insert(e);
	return kf;
}
}  // namespace mrpt_yesslam
