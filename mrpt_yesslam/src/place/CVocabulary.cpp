#include "mrpt_yesslam/place/CVocabulary.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
#include <numeric>
#include <random>
#include <thread>

#include "mrpt_yesslam/util/CWorkerPool.h"

#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/BinaryIO.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ShareDir.h"

namespace mrpt_yesslam
{
namespace
{
using TDesc = std::array<std::uint64_t, 4>;

inline int hamming(const TDesc& a, const TDesc& b)
{
	return __builtin_popcountll(a[0] ^ b[0]) + __builtin_popcountll(a[1] ^ b[1]) + __builtin_popcountll(a[2] ^ b[2]) +
		   __builtin_popcountll(a[3] ^ b[3]);
}

inline TDesc toDesc(const std::uint8_t* p)
{
	TDesc d;
	std::memcpy(d.data(), p, 32);
	return d;
}

// Bitwise majority of the members: each bit set when more than half the members have it.
TDesc majority(const std::vector<TDesc>& all, const std::vector<std::uint32_t>& members)
{
	std::array<std::uint32_t, 256> ones{};
	for (const auto m : members)
		for (int w = 0; w < 4; w++)
		{
			std::uint64_t v = all[m][w];
			while (v)
			{
				ones[w * 64 + __builtin_ctzll(v)]++;
				v &= v - 1;
			}
		}
	TDesc c{};
	for (int b = 0; b < 256; b++)
		if (2 * static_cast<std::size_t>(ones[b]) > members.size()) c[b / 64] |= std::uint64_t(1) << (b % 64);
	return c;
}

constexpr char kMagic[8] = {'Y', 'E', 'S', 'V', 'O', 'C', 'A', 'B'};
}  // namespace

/** A node of the tree while training (flattened breadth first afterwards). */
struct CVocabulary::TTreeNode
{
	TDesc centroid{};
	std::vector<TTreeNode> children;
};

namespace
{
// One level of k-majority clustering of `members` into at most k clusters (empty ones dropped).
// DBoW2's rule: a set of at most k descriptors gives one cluster per descriptor.
std::vector<std::pair<TDesc, std::vector<std::uint32_t>>> cluster(const std::vector<TDesc>& all,
																  const std::vector<std::uint32_t>& members, int k,
																  int maxIterations, std::mt19937_64& rng)
{
	std::vector<std::pair<TDesc, std::vector<std::uint32_t>>> out;
	if (members.size() <= static_cast<std::size_t>(k))
	{
		for (const auto m : members) out.push_back({all[m], {m}});
		return out;
	}
	// k-means++ seeding: each next centre drawn with probability proportional to the squared
	// distance to the nearest centre chosen so far.
	std::vector<TDesc> centres;
	centres.push_back(all[members[std::uniform_int_distribution<std::size_t>(0, members.size() - 1)(rng)]]);
	std::vector<double> d2(members.size());
	for (std::size_t i = 0; i < members.size(); i++)
	{
		const double d = hamming(all[members[i]], centres[0]);
		d2[i] = d * d;
	}
	while (centres.size() < static_cast<std::size_t>(k))
	{
		const double total = std::accumulate(d2.begin(), d2.end(), 0.0);
		if (total <= 0) break;  // fewer distinct descriptors than k
		double r = std::uniform_real_distribution<double>(0, total)(rng);
		std::size_t pick = 0;
		for (; pick + 1 < members.size(); pick++)
		{
			r -= d2[pick];
			if (r <= 0 && d2[pick] > 0) break;
		}
		centres.push_back(all[members[pick]]);
		for (std::size_t i = 0; i < members.size(); i++)
		{
			const double d = hamming(all[members[i]], centres.back());
			d2[i] = std::min(d2[i], d * d);
		}
	}
	std::vector<std::uint32_t> assign(members.size(), UINT32_MAX);
	std::vector<std::vector<std::uint32_t>> groups;
	for (int it = 0; it < maxIterations; it++)
	{
		bool changed = false;
		groups.assign(centres.size(), {});
		for (std::size_t i = 0; i < members.size(); i++)
		{
			const auto& d = all[members[i]];
			std::uint32_t best = 0;
			int bestDist = hamming(d, centres[0]);
			for (std::uint32_t c = 1; c < centres.size(); c++)
			{
				const int dist = hamming(d, centres[c]);
				if (dist < bestDist) bestDist = dist, best = c;
			}
			if (assign[i] != best) changed = true;
			assign[i] = best;
			groups[best].push_back(members[i]);
		}
		if (!changed) break;
		for (std::size_t c = 0; c < centres.size(); c++)
			if (!groups[c].empty()) centres[c] = majority(all, groups[c]);
	}
	for (std::size_t c = 0; c < centres.size(); c++)
		if (!groups[c].empty()) out.push_back({centres[c], std::move(groups[c])});
	return out;
}
}  // namespace

CVocabulary CVocabulary::train(const std::vector<cv::Mat>& images, const TTrainOptions& o,
							   const std::function<void(std::size_t, std::size_t)>& progress)
{
	if (o.branching < 2 || o.branching > 255) throw InputError("", "vocabulary branching factor must be 2..255");
	if (o.levels < 1 || o.levels > 10) throw InputError("", "vocabulary levels must be 1..10");
	if (std::pow(double(o.branching), double(o.levels)) > 4e9)
		throw InputError("", "vocabulary too large: branching^levels must stay below 4e9 words");
	if (o.maxIterations < 1) throw InputError("", "vocabulary k-majority iterations must be at least 1");
	std::vector<TDesc> all;
	for (const auto& m : images)
	{
		if (m.empty()) continue;
		if (m.type() != CV_8U || m.cols != 32)
			throw InputError("", "vocabulary training needs ORB descriptors (32-byte CV_8U rows)");
		for (int r = 0; r < m.rows; r++) all.push_back(toDesc(m.ptr<std::uint8_t>(r)));
	}
	if (all.empty()) throw InputError("", "no descriptors to train a vocabulary from");

	// The root is split here; its subtrees are independent, so they are built in parallel, each
	// with its own generator seeded from the options' seed and its index: the result does not
	// depend on the number of threads.
	std::vector<std::uint32_t> everyone(all.size());
	std::iota(everyone.begin(), everyone.end(), 0u);
	std::mt19937_64 rootRng(o.seed);
	auto top = cluster(all, everyone, o.branching, o.maxIterations, rootRng);
	everyone = {};
	TTreeNode root;
	root.children.resize(top.size());
	std::function<void(TTreeNode&, std::vector<std::uint32_t>&, int, std::mt19937_64&)> grow =
		[&](TTreeNode& node, std::vector<std::uint32_t>& members, int depth, std::mt19937_64& rng)
	{
		if (depth >= o.levels) return;
		auto parts = cluster(all, members, o.branching, o.maxIterations, rng);
		members = {};
		node.children.resize(parts.size());
		for (std::size_t c = 0; c < parts.size(); c++)
		{
			node.children[c].centroid = parts[c].first;
			if (parts[c].second.size() > 1) grow(node.children[c], parts[c].second, depth + 1, rng);
		}
	};
	std::atomic<std::size_t> next{0}, done{0};
	std::mutex progressMtx;
	const unsigned nThreads =
		std::max(1u, std::min<unsigned>(o.threads > 0 ? o.threads : std::thread::hardware_concurrency(), top.size()));
	auto worker = [&]
	{
		try
		{
			for (std::size_t c; (c = next++) < top.size();)
			{
				root.children[c].centroid = top[c].first;
				std::mt19937_64 rng(o.seed * 1000003ull + c + 1);
				if (top[c].second.size() > 1) grow(root.children[c], top[c].second, 1, rng);
				const auto d = ++done;
				if (progress)
				{
					std::lock_guard lk(progressMtx);
					progress(d, top.size());
				}
			}
		}
		catch (...)
		{
			next = top.size();  // the other workers stop after their subtree
			throw;
		}
	};
	// On the stage mechanism (CWorkerPool): what a worker throws (bad_alloc, the progress callback)
	// comes back through its future and is rethrown here once all have stopped; on bare threads it
	// called std::terminate.
	std::exception_ptr failure;
	{
		std::vector<std::future<void>> helpers;
		std::unique_ptr<CWorkerPool> pool;
		if (nThreads > 1)
		{
			pool = std::make_unique<CWorkerPool>(nThreads - 1);
			for (unsigned t = 1; t < nThreads; t++) helpers.push_back(pool->submit(worker));
		}
		try
		{
			worker();
		}
		catch (...)
		{
			failure = std::current_exception();
		}
		for (auto& f : helpers)
		{
			try
			{
				f.get();
			}
			catch (...)
			{
				if (!failure) failure = std::current_exception();
			}
		}
	}
	if (failure) std::rethrow_exception(failure);

	// Flatten breadth first: the children of a node get consecutive ids.
	CVocabulary v;
	v.k_ = o.branching;
	v.levels_ = o.levels;
	std::deque<const TTreeNode*> queue{&root};
	v.desc_.push_back(root.centroid);
	v.firstChild_.push_back(0);
	v.numChildren_.push_back(0);
	v.wordOfNode_.push_back(UINT32_MAX);
	std::uint32_t words = 0;
	for (std::size_t id = 0; !queue.empty(); id++)
	{
		const TTreeNode* n = queue.front();
		queue.pop_front();
		v.firstChild_[id] = static_cast<std::uint32_t>(v.desc_.size());
		v.numChildren_[id] = static_cast<std::uint8_t>(n->children.size());
		if (n->children.empty()) v.wordOfNode_[id] = words++;
		for (const auto& ch : n->children)
		{
			queue.push_back(&ch);
			v.desc_.push_back(ch.centroid);
			v.firstChild_.push_back(0);
			v.numChildren_.push_back(0);
			v.wordOfNode_.push_back(UINT32_MAX);
		}
	}

	// IDF from the finished tree (each training descriptor descends it as a query would).
	std::vector<std::uint32_t> imagesWith(words, 0), lastImage(words, UINT32_MAX);
	std::uint32_t imageIndex = 0;
	for (const auto& m : images)
	{
		if (m.empty()) continue;
		for (int r = 0; r < m.rows; r++)
		{
			const auto w = v.word(m.ptr<std::uint8_t>(r));
			if (lastImage[w] != imageIndex) lastImage[w] = imageIndex, imagesWith[w]++;
		}
		imageIndex++;
	}
	v.trainingImages_ = imageIndex;
	v.idf_.resize(words);
	for (std::uint32_t w = 0; w < words; w++)
		v.idf_[w] = imagesWith[w] ? static_cast<float>(std::log(double(imageIndex) / imagesWith[w]))
								  : static_cast<float>(std::log(double(imageIndex)));
	return v;
}

std::uint32_t CVocabulary::word(const std::uint8_t* descriptor, std::uint32_t* node, int nodeLevel) const
{
	const TDesc d = toDesc(descriptor);
	std::uint32_t n = 0;
	int depth = 0;
	if (node && nodeLevel <= 0) *node = 0;
	while (numChildren_[n])
	{
		const std::uint32_t first = firstChild_[n], end = first + numChildren_[n];
		std::uint32_t best = first;
		int bestDist = hamming(d, desc_[first]);
		for (std::uint32_t c = first + 1; c < end; c++)
		{
			const int dist = hamming(d, desc_[c]);
			if (dist < bestDist) bestDist = dist, best = c;
		}
		n = best;
		if (node && ++depth == nodeLevel) *node = n;
	}
	if (node && depth < nodeLevel) *node = n;
	return wordOfNode_[n];
}

void CVocabulary::transform(const cv::Mat& descriptors, TBowVector& bow, TFeatureVector* direct, int directLevel,
							const std::vector<bool>& use) const
{
	bow.clear();
	if (direct) direct->clear();
	if (descriptors.empty() || numWords() == 0) return;
	if (descriptors.type() != CV_8U || descriptors.cols != 32)
		throw std::invalid_argument("CVocabulary::transform needs 32-byte ORB descriptors");
	bow.reserve(descriptors.rows);
	for (int r = 0; r < descriptors.rows; r++)
	{
		if (!use.empty() && !use[r]) continue;
		std::uint32_t node = 0;
		const auto w = word(descriptors.ptr<std::uint8_t>(r), direct ? &node : nullptr, directLevel);
		// TF-IDF as DBoW2: every occurrence adds the word's IDF, then the vector is L1-normalised.
		// A word seen in every training image (IDF 0) says nothing about the place.
		if (idf_[w] > 0) bow.emplace_back(w, idf_[w]);
		if (direct) (*direct)[node].push_back(static_cast<std::uint32_t>(r));
	}
	std::sort(bow.begin(), bow.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
	std::size_t out = 0;
	double total = 0;
	for (std::size_t i = 0; i < bow.size(); i++)
	{
		total += bow[i].second;
		if (out > 0 && bow[out - 1].first == bow[i].first)
			bow[out - 1].second += bow[i].second;
		else
			bow[out++] = bow[i];
	}
	bow.resize(out);
	if (total > 0)
		for (auto& [w, x] : bow) x = static_cast<float>(x / total);
}

std::shared_ptr<const TBow> CVocabulary::bowOf(const TFeatures& f, int directLevel) const
{
	auto bow = std::make_shared<TBow>();
	std::vector<bool> use(f.keypoints.size());
	for (std::size_t i = 0; i < use.size(); i++) use[i] = !f.dynamic[i] && !f.isUncertain(i);
	transform(f.descriptors, bow->words, &bow->direct, directLevel, use);
	return bow;
}

std::string CVocabulary::shippedPath()
{
	const std::string dir = shareDir();
	return dir.empty() ? std::string() : dir + "/vocabulary/orb_k10_L5.yvoc";
}

double CVocabulary::score(const TBowVector& a, const TBowVector& b)
{
	double s = 0;
	auto i = a.begin(), j = b.begin();
	while (i != a.end() && j != b.end())
	{
		if (i->first < j->first)
			++i;
		else if (j->first < i->first)
			++j;
		else
		{
			s += std::abs(i->second) + std::abs(j->second) - std::abs(i->second - j->second);
			++i, ++j;
		}
	}
	return 0.5 * s;
}

void CVocabulary::save(const std::string& path) const
{
	std::string buf;
	auto put = [&](const void* p, std::size_t n) { buf.append(static_cast<const char*>(p), n); };
	auto put32 = [&](std::uint32_t x) { put(&x, 4); };
	put(kMagic, 8);
	put32(kFileVersion);
	put32(static_cast<std::uint32_t>(k_));
	put32(static_cast<std::uint32_t>(levels_));
	put(&trainingImages_, 8);
	put32(static_cast<std::uint32_t>(desc_.size()));
	put32(static_cast<std::uint32_t>(idf_.size()));
	put32(static_cast<std::uint32_t>(description_.size()));
	put(description_.data(), description_.size());
	put(desc_.data(), desc_.size() * sizeof(TDesc));
	put(firstChild_.data(), firstChild_.size() * 4);
	put(numChildren_.data(), numChildren_.size());
	put(wordOfNode_.data(), wordOfNode_.size() * 4);
	put(idf_.data(), idf_.size() * 4);
	const std::uint64_t sum = binio::checksum(buf.data(), buf.size());
	put(&sum, 8);
	writeFileAtomically(path, buf);
}

std::uint64_t CVocabulary::fingerprint() const
{
	std::string buf;
	const auto add = [&buf](const void* p, std::size_t n) { buf.append(static_cast<const char*>(p), n); };
	const std::uint32_t head[2] = {static_cast<std::uint32_t>(k_), static_cast<std::uint32_t>(levels_)};
	add(head, sizeof(head));
	add(desc_.data(), desc_.size() * sizeof(TDesc));
	add(firstChild_.data(), firstChild_.size() * 4);
	add(numChildren_.data(), numChildren_.size());
	add(wordOfNode_.data(), wordOfNode_.size() * 4);
	add(idf_.data(), idf_.size() * 4);
	return binio::checksum(buf.data(), buf.size());
}

CVocabulary CVocabulary::load(const std::string& path)
{
	std::ifstream f(path, std::ios::binary | std::ios::ate);
	if (!f) throw InputError(path, "cannot open the vocabulary file");
	const auto size = static_cast<std::size_t>(f.tellg());
	if (size > (std::size_t(1) << 31)) throw InputError(path, "not a yesslam vocabulary (larger than 2 GB)");
	std::string buf(size, '\0');
	f.seekg(0);
	if (!f.read(buf.data(), static_cast<std::streamsize>(size)))
		throw InputError(path, "cannot read the vocabulary file");
	if (size < 8 || std::memcmp(buf.data(), kMagic, 8) != 0)
		throw InputError(path,
						 "not a yesslam vocabulary (train one with yesslam-vocab; DBoW2/DBoW3 files are not read)");
	if (size < 8 + 8 + 4 * 6 + 8) throw InputError(path, "vocabulary file is truncated");
	std::uint64_t stored;
	std::memcpy(&stored, buf.data() + size - 8, 8);
	std::size_t pos = 8;
	auto get = [&](void* p, std::size_t n)
	{
		if (pos + n > size - 8) throw InputError(path, "vocabulary file is truncated");
		std::memcpy(p, buf.data() + pos, n);
		pos += n;
	};
	auto get32 = [&]
	{
		std::uint32_t x;
		get(&x, 4);
		return x;
	};
	const auto version = get32();
	if (version == 0 || version > kFileVersion)
		throw InputError(path, "vocabulary format version " + std::to_string(version) + ", this build reads up to " +
								   std::to_string(kFileVersion));
	if (binio::checksum(buf.data(), size - 8) != stored)
		throw InputError(path, "vocabulary file is corrupt (checksum mismatch)");
	CVocabulary v;
	v.k_ = static_cast<int>(get32());
	v.levels_ = static_cast<int>(get32());
	get(&v.trainingImages_, 8);
	const auto nodes = get32(), words = get32(), descLen = get32();
	if (nodes == 0 || words == 0 || words > nodes || descLen > (1u << 20) || v.k_ < 2 || v.k_ > 255 || v.levels_ < 1 ||
		v.levels_ > 10)
		throw InputError(path, "vocabulary header is inconsistent");
	v.description_.resize(descLen);
	get(v.description_.data(), descLen);
	if (pos + std::size_t(nodes) * (32 + 4 + 1 + 4) + std::size_t(words) * 4 != size - 8)
		throw InputError(path, "vocabulary file has the wrong size for its header");
	v.desc_.resize(nodes);
	v.firstChild_.resize(nodes);
	v.numChildren_.resize(nodes);
	v.wordOfNode_.resize(nodes);
	v.idf_.resize(words);
	get(v.desc_.data(), nodes * sizeof(TDesc));
	get(v.firstChild_.data(), nodes * 4);
	get(v.numChildren_.data(), nodes);
	get(v.wordOfNode_.data(), nodes * 4);
	get(v.idf_.data(), words * 4);
	// The checksum catches damage; this catches a well-formed file whose tree would send a lookup
	// out of bounds or into a loop (children always come after their parent, words are leaves).
	for (std::uint32_t n = 0; n < nodes; n++)
	{
		const auto c = v.numChildren_[n];
		if (c == 0 ? v.wordOfNode_[n] >= words
				   : (c > v.k_ || v.firstChild_[n] <= n || std::size_t(v.firstChild_[n]) + c > nodes))
			throw InputError(path, "vocabulary tree is inconsistent");
	}
	return v;
}
}  // namespace mrpt_yesslam
