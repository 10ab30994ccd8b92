#include "mrpt_yesslam/sim/CSimWorld.h"

#include <mrpt/img/CImage.h>
#include <mrpt/opengl/COpenGLViewport.h>
#include <mrpt/opengl/CSetOfTexturedTriangles.h>

#include <cmath>
#include <random>

#include "mrpt_yesslam/sim/SimTextures.h"

namespace mrpt_yesslam
{
namespace
{
using mrpt::poses::CPose3D;
constexpr double kDeg = M_PI / 180.0;

TSimBox box(double x, double y, double z, double sx, double sy, double sz, int tex, double yaw = 0)
{
	TSimBox b;
	b.local = CPose3D(x, y, z, yaw, 0, 0);
	b.sx = sx;
	b.sy = sy;
	b.sz = sz;
	b.texture = tex;
	return b;
}

// 12 textured triangles of a box centred at the origin, the texture stretched over each face.
mrpt::opengl::CSetOfTexturedTriangles::Ptr texturedBox(double sx, double sy, double sz, const cv::Mat& tex)
{
	auto obj = mrpt::opengl::CSetOfTexturedTriangles::Create();
	const float hx = static_cast<float>(sx / 2), hy = static_cast<float>(sy / 2), hz = static_cast<float>(sz / 2);
	using P = mrpt::math::TPoint3Df;
	const P c[8] = {{-hx, -hy, -hz}, {hx, -hy, -hz}, {hx, hy, -hz}, {-hx, hy, -hz},
					{-hx, -hy, hz},  {hx, -hy, hz},  {hx, hy, hz},  {-hx, hy, hz}};
	// Faces as corner indices, counter-clockwise seen from outside.
	const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {3, 0, 4, 7}};
	for (const auto& f : faces)
	{
		const float uv[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
		for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}})
		{
			mrpt::opengl::TTriangle t(c[f[tri[0]]], c[f[tri[1]]], c[f[tri[2]]]);
			for (int k = 0; k < 3; k++)
			{
				t.vertices[k].uv = mrpt::math::TVector2Df(uv[tri[k]][0], uv[tri[k]][1]);
				t.vertices[k].setColor(mrpt::img::TColor(255, 255, 255, 255));
			}
			t.computeNormals();
			obj->insertTriangle(t);
		}
	}
	obj->assignImage(mrpt::img::CImage(tex, mrpt::img::DEEP_COPY));
	return obj;
}
}  // namespace

int CSimWorld::texture(const cv::Scalar& base, int size, double density)
{
	if (!photos_.empty())
	{
		textures_.push_back(photos_[texCounter_++ % photos_.size()]);
		return static_cast<int>(textures_.size()) - 1;
	}
	textures_.push_back(makeClutterTexture(seed_ * 7919u + texCounter_++, size, base, density));
	return static_cast<int>(textures_.size()) - 1;
}

int CSimWorld::addObject(TSimObject o)
{
	o.id = static_cast<int>(objects_.size()) + 1;
	objects_.push_back(std::move(o));
	return static_cast<int>(objects_.size()) - 1;
}

int CSimWorld::indexOfId(int id) const
{
	return (id >= 1 && id <= static_cast<int>(objects_.size())) ? id - 1 : -1;
}

CSimWorld::CSimWorld(uint32_t seed, const std::vector<cv::Mat>& photos, bool bareWalls) : seed_(seed), photos_(photos)
{
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> u(0, 1);
	auto jitter = [&](double a) { return (u(rng) - 0.5) * 2 * a; };
	auto structure = [&](const std::string& name, TSimBox b)
	{
		TSimObject o;
		o.name = name;
		o.boxes = {b};
		addObject(o);
	};
	// Room shell: boxes just outside the 6 x 5 x 3 m interior. Painted walls, floor and ceiling carry
	// few marks: in real TUM frames only about half of the 32x32 cells off the people hold a clear
	// corner (FAST 20; bench/bench_feature_share), where surfaces covered in clutter made it 98 %.
	structure("floor", box(3, 2.5, -0.05, 6.2, 5.2, 0.1, texture({70, 90, 120}, 1024, 0.1)));
	structure("ceiling", box(3, 2.5, 3.05, 6.2, 5.2, 0.1, texture({220, 225, 225}, 512, 0.03)));
	structure("wall far", box(6.05, 2.5, 1.5, 0.1, 5.2, 3.1, texture({170, 190, 200}, 1024, 0.06)));
	structure("wall near", box(-0.05, 2.5, 1.5, 0.1, 5.2, 3.1, texture({160, 170, 190}, 1024, 0.06)));
	structure("wall left", box(3, 5.05, 1.5, 6.2, 0.1, 3.1, texture({190, 180, 160}, 1024, 0.06)));
	structure("wall right", box(3, -0.05, 1.5, 6.2, 0.1, 3.1, texture({150, 175, 180}, 1024, 0.06)));
	// Posters and boards on the walls: dense texture at eye height, on every wall (not on bare
	// walls; the random draws are made all the same, so the furniture stays where it is).
	const auto poster = [&](const std::string& name, TSimBox b)
	{
		if (!bareWalls) structure(name, b);
	};
	for (int i = 0; i < 4; i++)
		poster("poster", box(5.99, 0.7 + i * 1.2 + jitter(0.15), 1.6 + jitter(0.2), 0.02, 0.6 + jitter(0.1),
							 0.8 + jitter(0.1), texture({200, 200, 200}, 256)));
	for (int i = 0; i < 2; i++)
	{
		poster("poster", box(0.01, 1.2 + i * 2.4 + jitter(0.15), 1.6 + jitter(0.2), 0.02, 0.7 + jitter(0.1),
							 0.9 + jitter(0.1), texture({190, 200, 210}, 256)));
		poster("poster", box(1.5 + i * 2.5 + jitter(0.15), 4.99, 1.6 + jitter(0.2), 0.7 + jitter(0.1), 0.02,
							 0.9 + jitter(0.1), texture({210, 200, 190}, 256)));
		poster("poster", box(1.2 + i * 2.5 + jitter(0.15), 0.01, 1.6 + jitter(0.2), 0.7 + jitter(0.1), 0.02,
							 0.9 + jitter(0.1), texture({200, 210, 200}, 256)));
	}

	// Desks with what stands on them. (x, y, yaw): two against the far wall, one at each side wall.
	const double desks[4][3] = {{5.3, 1.55, 90}, {5.3, 3.45, 90}, {3.4, 4.6, 180}, {3.2, 0.4, 0}};
	for (int d = 0; d < 4; d++)
	{
		const CPose3D base(desks[d][0] + jitter(0.05), desks[d][1] + jitter(0.05), 0, (desks[d][2] + jitter(3)) * kDeg,
						   0, 0);
		TSimObject desk;
		desk.name = "desk";
		desk.classId = 60;  // dining table
		desk.pose = base;
		const int tt = texture({120 + 40 * u(rng), 140, 160});
		desk.boxes.push_back(box(0, 0, 0.72, 1.4, 0.7, 0.04, tt));
		for (int lx : {-1, 1})
			for (int ly : {-1, 1}) desk.boxes.push_back(box(lx * 0.65, ly * 0.3, 0.35, 0.05, 0.05, 0.7, tt));
		addObject(desk);
		// On the desk, in desk coordinates (x along the desk, y towards the back).
		auto onDesk = [&](const std::string& name, int cls, std::vector<TSimBox> boxes)
		{
			TSimObject o;
			o.name = name;
			o.classId = cls;
			o.pose = base;
			o.boxes = std::move(boxes);
			addObject(o);
		};
		const int tv = texture({40, 40, 40});
		onDesk("monitor", 62, {box(0.1, 0.2, 1.02, 0.56, 0.04, 0.36, tv), box(0.1, 0.22, 0.82, 0.06, 0.04, 0.2, tv)});
		onDesk("keyboard", 66, {box(0.05, -0.12, 0.755, 0.45, 0.15, 0.03, texture({60, 60, 60}, 128))});
		onDesk("mouse", 64, {box(0.4, -0.1, 0.755, 0.06, 0.1, 0.03, texture({200, 200, 200}, 64))});
		onDesk("cup", 41, {box(-0.5 + jitter(0.05), 0.05, 0.79, 0.08, 0.08, 0.1, texture({40, 40, 200}, 64))});
		if (u(rng) < 0.7) onDesk("bottle", 39, {box(-0.4, 0.2, 0.865, 0.07, 0.07, 0.25, texture({60, 160, 60}, 64))});
		std::vector<TSimBox> books;
		for (int b = 0; b < 2 + static_cast<int>(rng() % 3); b++)
			books.push_back(box(-0.55, 0.25, 0.76 + 0.035 * b, 0.22, 0.16, 0.03,
								texture({100 + 100 * u(rng), 80, 160}, 64), jitter(0.2)));
		onDesk("book", 73, books);
		// A chair in front of the desk.
		TSimObject chair;
		chair.name = "chair";
		chair.classId = 56;
		chair.pose = base + CPose3D(jitter(0.2), -0.65 + jitter(0.05), 0, (90 + jitter(15)) * kDeg, 0, 0);
		const int ct = texture({50, 50, 150 + 60 * u(rng)}, 128);
		chair.boxes = {box(0, 0, 0.46, 0.45, 0.45, 0.06, ct), box(-0.21, 0, 0.72, 0.05, 0.45, 0.48, ct),
					   box(0, 0, 0.22, 0.06, 0.06, 0.44, ct)};
		addObject(chair);
	}
	// A shelf with books in the far right corner.
	{
		const CPose3D base(5.75, 0.35, 0, 90 * kDeg, 0, 0);
		TSimObject shelf;
		shelf.name = "shelf";
		shelf.pose = base;
		const int st = texture({90, 120, 150}, 256);
		for (int level = 0; level < 4; level++)
			shelf.boxes.push_back(box(0, 0, 0.3 + 0.45 * level, 0.9, 0.35, 0.03, st));
		shelf.boxes.push_back(box(-0.44, 0, 0.95, 0.02, 0.35, 1.9, st));
		shelf.boxes.push_back(box(0.44, 0, 0.95, 0.02, 0.35, 1.9, st));
		addObject(shelf);
		TSimObject books;
		books.name = "book";
		books.classId = 73;
		books.pose = base;
		for (int level = 0; level < 3; level++)
			for (int b = 0; b < 8; b++)
				books.boxes.push_back(box(-0.38 + b * 0.1 + jitter(0.01), 0, 0.3 + 0.45 * level + 0.13,
										  0.05 + jitter(0.015), 0.25, 0.22 + jitter(0.04),
										  texture({80 + 150 * u(rng), 60 + 150 * u(rng), 60 + 150 * u(rng)}, 64)));
		addObject(books);
	}
	// Plants in corners.
	for (const auto& c :
		 {std::array<double, 2>{5.6, 4.6}, std::array<double, 2>{0.5, 4.5}, std::array<double, 2>{4.4, 0.35}})
	{
		TSimObject plant;
		plant.name = "potted plant";
		plant.classId = 58;
		plant.pose = CPose3D(c[0], c[1], 0, jitter(M_PI), 0, 0);
		plant.boxes = {box(0, 0, 0.15, 0.3, 0.3, 0.3, texture({40, 80, 140}, 64)),
					   box(0, 0, 0.65, 0.5, 0.5, 0.7, texture({40, 140, 50}, 128))};
		addObject(plant);
	}
}

void CSimWorld::addWalkingPerson(const std::vector<mrpt::math::TPoint2D>& path, double speed, double phase)
{
	TSimObject o;
	o.name = "person";
	o.classId = 0;
	o.moves = true;
	const int shirt = texture({static_cast<double>(60 + (people_.size() * 70) % 180), 90, 140}, 128);
	const int trousers = texture({80, 60, 40}, 128);
	const int skin = texture({150, 170, 210}, 64);
	o.boxes = {box(0, 0, 1.15, 0.22, 0.38, 0.55, shirt), box(0, 0, 1.6, 0.2, 0.18, 0.24, skin),
			   box(0, 0.1, 0.44, 0.13, 0.13, 0.88, trousers), box(0, -0.1, 0.44, 0.13, 0.13, 0.88, trousers),
			   box(0, 0.235, 1.1, 0.09, 0.09, 0.62, shirt), box(0, -0.235, 1.1, 0.09, 0.09, 0.62, shirt),
			   // The neck, and arms that touch the torso: head and arms of a real person are connected
			   // to the body, which is what a depth flood fill from the torso relies on.
			   box(0, 0, 1.45, 0.1, 0.1, 0.12, skin)};
	for (int k = 0; k < 4; k++) o.boxes[static_cast<std::size_t>(2 + k)].limb = k;
	TSimPerson p;
	p.object = addObject(o);
	p.path = path;
	p.speed = speed;
	p.phase = phase;
	people_.push_back(p);
}

void CSimWorld::addSittingPerson(const mrpt::poses::CPose3D& seat, double phase)
{
	TSimObject o;
	o.name = "person";
	o.classId = 0;
	o.moves = true;
	const int shirt = texture({static_cast<double>(120 + (people_.size() * 50) % 120), 60, 60}, 128);
	const int trousers = texture({70, 70, 90}, 128);
	const int skin = texture({150, 170, 210}, 64);
	o.boxes = {box(0, 0, 0.78, 0.22, 0.38, 0.55, shirt),
			   box(0, 0, 1.2, 0.2, 0.18, 0.24, skin),
			   box(0.22, 0.1, 0.5, 0.45, 0.13, 0.13, trousers),
			   box(0.22, -0.1, 0.5, 0.45, 0.13, 0.13, trousers),
			   box(0.45, 0.1, 0.25, 0.12, 0.12, 0.45, trousers),
			   box(0.45, -0.1, 0.25, 0.12, 0.12, 0.45, trousers),
			   box(0.2, 0.235, 0.85, 0.5, 0.09, 0.09, shirt),
			   box(0.2, -0.235, 0.85, 0.5, 0.09, 0.09, shirt),
			   box(0, 0, 1.08, 0.1, 0.1, 0.1, skin)};  // neck
	o.boxes[1].limb = 10;                              // head nods
	o.boxes[6].limb = 11;                              // arms move
	o.boxes[7].limb = 12;
	TSimPerson p;
	p.object = addObject(o);
	p.sitting = true;
	p.seat = seat;
	p.phase = phase;
	people_.push_back(p);
}

void CSimWorld::addMovingChair(const std::vector<mrpt::math::TPoint2D>& path, double speed)
{
	TSimObject chair;
	chair.name = "chair";
	chair.classId = 56;
	chair.moves = true;
	const int ct = texture({30, 140, 200}, 128);
	chair.boxes = {box(0, 0, 0.46, 0.45, 0.45, 0.06, ct), box(-0.21, 0, 0.72, 0.05, 0.45, 0.48, ct),
				   box(0, 0, 0.22, 0.06, 0.06, 0.44, ct)};
	chairObjects_.push_back(addObject(chair));
	chairPaths_.emplace_back(path, speed);
}

namespace
{
// Position and heading along a polyline walked back and forth at constant speed.
void alongPath(const std::vector<mrpt::math::TPoint2D>& path, double dist, double& x, double& y, double& yaw)
{
	double total = 0;
	for (std::size_t i = 1; i < path.size(); i++) total += (path[i] - path[i - 1]).norm();
	if (path.size() < 2 || total <= 0)
	{
		x = path.empty() ? 0 : path[0].x;
		y = path.empty() ? 0 : path[0].y;
		yaw = 0;
		return;
	}
	double d = std::fmod(dist, 2 * total);
	bool back = d > total;
	if (back) d = 2 * total - d;
	for (std::size_t i = 1; i < path.size(); i++)
	{
		const double len = (path[i] - path[i - 1]).norm();
		if (d <= len || i + 1 == path.size())
		{
			const double f = len > 0 ? std::min(1.0, d / len) : 0;
			x = path[i - 1].x + f * (path[i].x - path[i - 1].x);
			y = path[i - 1].y + f * (path[i].y - path[i - 1].y);
			yaw = std::atan2(path[i].y - path[i - 1].y, path[i].x - path[i - 1].x) + (back ? M_PI : 0);
			return;
		}
		d -= len;
	}
}
}  // namespace

void CSimWorld::animatePerson(const TSimPerson& p, double t, TSimObject& o) const
{
	if (p.sitting)
	{
		// Slight sway of the whole body (and chair), head nods, arms typing.
		o.pose = p.seat + CPose3D(0.02 * std::sin(0.5 * t + p.phase), 0, 0, 0.05 * std::sin(0.3 * t + p.phase), 0, 0);
		const double nod = 0.15 * std::sin(0.9 * t + p.phase);
		o.boxes[1].local = CPose3D(0, 0, 1.05, 0, 0, 0) + CPose3D(0, 0, 0, 0.3 * std::sin(0.4 * t), nod, 0) +
						   CPose3D(0, 0, 0.15, 0, 0, 0);
		for (int k = 0; k < 2; k++)
		{
			const double side = k == 0 ? 0.235 : -0.235;
			const double a = 0.25 * std::sin(1.7 * t + p.phase + k * 1.3);
			o.boxes[static_cast<std::size_t>(6 + k)].local =
				CPose3D(0, side, 1.0, 0, 0.6 + a, 0) + CPose3D(0.25, 0, 0, 0, 0, 0);
		}
		return;
	}
	double x, y, yaw;
	alongPath(p.path, p.speed * t, x, y, yaw);
	// Gait: legs swing about the hip, arms opposite, one stride per 1.2 m.
	const double w = 2 * M_PI * p.speed / 1.2;
	const double s = std::sin(w * t + p.phase);
	o.pose = CPose3D(x, y, 0.02 * std::abs(std::cos(w * t + p.phase)), yaw, 0, 0);
	const double legs[2] = {0.45 * s, -0.45 * s};
	const double arms[2] = {-0.35 * s, 0.35 * s};
	for (int k = 0; k < 2; k++)
	{
		const double side = k == 0 ? 0.1 : -0.1;
		o.boxes[static_cast<std::size_t>(2 + k)].local =
			CPose3D(0, side, 0.88, 0, legs[k], 0) + CPose3D(0, 0, -0.44, 0, 0, 0);
		const double aside = k == 0 ? 0.235 : -0.235;
		o.boxes[static_cast<std::size_t>(4 + k)].local =
			CPose3D(0, aside, 1.4, 0, arms[k], 0) + CPose3D(0, 0, -0.31, 0, 0, 0);
	}
}

mrpt::opengl::CSetOfObjects::Ptr CSimWorld::buildObject(const TSimObject& o) const
{
	auto set = mrpt::opengl::CSetOfObjects::Create();
	set->setName(o.name);  // yesslam-render --hide ceiling shows the room from inside
	set->setPose(o.pose);
	for (const auto& b : o.boxes)
	{
		auto c = texturedBox(b.sx, b.sy, b.sz, textures_[static_cast<std::size_t>(b.texture)]);
		c->setPose(b.local);
		set->insert(c);
	}
	return set;
}

void CSimWorld::setTime(double t)
{
	t_ = t;
	for (const auto& p : people_) animatePerson(p, t, objects_[static_cast<std::size_t>(p.object)]);
	for (std::size_t k = 0; k < chairObjects_.size(); k++)
	{
		double x, y, yaw;
		alongPath(chairPaths_[k].first, chairPaths_[k].second * t, x, y, yaw);
		objects_[static_cast<std::size_t>(chairObjects_[k])].pose = CPose3D(x, y, 0, yaw, 0, 0);
	}
}

std::vector<TRayBox> CSimWorld::rayBoxes() const
{
	std::vector<TRayBox> out;
	for (const auto& o : objects_)
		for (const auto& b : o.boxes)
		{
			TRayBox r;
			r.pose = o.pose + b.local;
			r.sx = b.sx;
			r.sy = b.sy;
			r.sz = b.sz;
			r.texture = &textures_[static_cast<std::size_t>(b.texture)];
			r.id = static_cast<uint16_t>(o.id);
			out.push_back(r);
		}
	return out;
}

mrpt::opengl::COpenGLScene::Ptr CSimWorld::scene(bool withMoving) const
{
	auto s = mrpt::opengl::COpenGLScene::Create();
	// The light the ray caster uses, so that the scene looks in a viewer as in the images.
	const CBoxRaycaster::TOptions light;
	auto& lp = s->getViewport()->lightParameters();
	lp.ambient = mrpt::img::TColorf(light.ambient, light.ambient, light.ambient, 1);
	lp.diffuse = mrpt::img::TColorf(light.diffuse, light.diffuse, light.diffuse, 1);
	lp.specular = mrpt::img::TColorf(0, 0, 0, 1);
	lp.direction = mrpt::math::TVector3Df(light.lightDir[0], light.lightDir[1], light.lightDir[2]);
	for (const auto& o : objects_)
		if (withMoving || !o.moves) s->insert(buildObject(o));
	return s;
}

std::vector<std::pair<mrpt::poses::CPose3D, TSimBox>> CSimWorld::worldBoxes(int idx) const
{
	std::vector<std::pair<CPose3D, TSimBox>> out;
	const auto& o = objects_[static_cast<std::size_t>(idx)];
	for (const auto& b : o.boxes) out.emplace_back(o.pose + b.local, b);
	return out;
}
}  // namespace mrpt_yesslam
