#include "mrpt_yesslam/data/CMapPoint.h"

#include <string>

#include <stdexcept>

#include "mrpt_yesslam/util/BinaryIO.h"

namespace mrpt_yesslam
{
void CMapPoint::serialize(std::ostream& o) const
{
	using namespace binio;
	put<std::uint32_t>(o, kSerialVersion);
	put<std::int64_t>(o, id);
	put(o, position.x);
	put(o, position.y);
	put(o, position.z);
	std::vector<std::uint8_t> d;
	if (!descriptor.empty())
		d.assign(descriptor.ptr<std::uint8_t>(0), descriptor.ptr<std::uint8_t>(0) + descriptor.total());
	putVector(o, d);
	for (int c = 0; c < 3; c++) put<std::uint8_t>(o, color[c]);
	std::vector<std::uint64_t> obs;
	for (const auto& [k, i] : observations)
	{
		obs.push_back(k);
		obs.push_back(i);
	}
	putVector(o, obs);
	put<std::uint64_t>(o, firstKeyFrame);
	put<std::int32_t>(o, visible);
	put<std::int32_t>(o, found);
	put<std::uint8_t>(o, bad);
	put<std::int64_t>(o, replacedBy);
}

CMapPoint CMapPoint::deserialize(std::istream& i)
{
	using namespace binio;
	getVersion(i, "map point", kSerialVersion);
	CMapPoint p;
	p.id = static_cast<TPointId>(get<std::int64_t>(i, "map point id"));
	p.position.x = get<double>(i, "map point position");
	p.position.y = get<double>(i, "map point position");
	p.position.z = get<double>(i, "map point position");
	// Exactly one ORB row: the matcher stacks point descriptors into one matrix by row, so an empty
	// one shifts every later point's row (reads out of bounds) and another length throws in tracking.
	const auto d = getVector<std::uint8_t>(i, "map point descriptor", 1024);
	if (d.size() != 32)
		throw std::runtime_error("map point descriptor of " + std::to_string(d.size()) +
								 " bytes, not one 32-byte ORB descriptor");
	p.descriptor = cv::Mat(1, 32, CV_8U, const_cast<std::uint8_t*>(d.data())).clone();
	for (int c = 0; c < 3; c++) p.color[c] = get<std::uint8_t>(i, "map point colour");
	const auto obs = getVector<std::uint64_t>(i, "map point observations");
	if (obs.size() % 2) throw std::runtime_error("odd observation list reading map point");
	for (std::size_t k = 0; k < obs.size(); k += 2) p.observations[obs[k]] = obs[k + 1];
	p.firstKeyFrame = get<std::uint64_t>(i, "map point first keyframe");
	p.visible = get<std::int32_t>(i, "map point counts");
	p.found = get<std::int32_t>(i, "map point counts");
	p.bad = get<std::uint8_t>(i, "map point flags") != 0;
	p.replacedBy = static_cast<TPointId>(get<std::int64_t>(i, "map point fusion"));
	return p;
}
}  // namespace mrpt_yesslam
