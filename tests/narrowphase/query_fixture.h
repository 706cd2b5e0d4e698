#pragma once
// Shared by the tree/query tests: every tree configuration, and the comparison of a query
// against the reference at one pose, in every mode.

#include "test_scale.h"

#include <kolize/engine/narrow_workload.h>
#include <kolize/narrowphase/mesh_query.h>
#include <kolize/narrowphase/reference.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace kolize::narrowphase::testing {

inline const std::vector<TreeKind>& allKinds() {
    static const std::vector<TreeKind> kinds = {
        TreeKind::kSphere, TreeKind::kAabb,   TreeKind::kObb,   TreeKind::kKdop6,
        TreeKind::kKdop14, TreeKind::kKdop18, TreeKind::kKdop26};
    return kinds;
}

/// Models of one mesh for every kind and leaf size 1..8, each validated after its build.
class ModelSet {
  public:
    explicit ModelSet(const std::shared_ptr<const TriangleMesh>& mesh) {
        for (TreeKind kind : allKinds()) {
            for (int leaf = 1; leaf <= 8; ++leaf) {
                models_.emplace(std::make_pair(kind, leaf),
                                std::make_unique<MeshModel>(mesh, TreeSettings{kind, leaf}));
                const std::string problem = models_.at({kind, leaf})->validate();
                EXPECT_EQ(problem, "")
                    << mesh->name() << " " << treeKindName(kind) << " leaf " << leaf;
            }
        }
    }
    const MeshModel& get(TreeKind kind, int leaf) const { return *models_.at({kind, leaf}); }

  private:
    std::map<std::pair<TreeKind, int>, std::unique_ptr<MeshModel>> models_;
};

inline std::string describe(const Pose& p) {
    std::ostringstream out;
    out.precision(17);
    out << "R = [" << p.rotation.row(0) << "; " << p.rotation.row(1) << "; " << p.rotation.row(2)
        << "], t = (" << p.translation.transpose() << ")";
    return out.str();
}

/// Mismatches of one configuration at one pose, all modes.
struct Mismatch {
    std::size_t missing = 0, extra = 0;
    bool yesNoWrong = false, contactsWrong = false;
    bool any() const { return missing || extra || yesNoWrong || contactsWrong; }
};

/// All pairs with the default descent (both trees at once), yes/no with FCL's (the larger
/// node), contacts with the thesis's (A first): every rule meets every mesh and tree.
inline Mismatch compareAtPose(const MeshModel& a, const Pose& pa, const MeshModel& b,
                              const Pose& pb, const std::vector<TrianglePair>& reference,
                              MeshQuery& query) {
    Mismatch m;
    QuerySettings settings;
    std::vector<TrianglePair> got = query.run(a, pa, b, pb, settings).pairs;
    std::sort(got.begin(), got.end());
    std::vector<TrianglePair> diff;
    std::set_difference(reference.begin(), reference.end(), got.begin(), got.end(),
                        std::back_inserter(diff));
    m.missing = diff.size();
    diff.clear();
    std::set_difference(got.begin(), got.end(), reference.begin(), reference.end(),
                        std::back_inserter(diff));
    m.extra = diff.size();
    settings.mode = QueryMode::kYesNo;
    settings.descent = Descent::kLarger;
    const QueryResult& yes = query.run(a, pa, b, pb, settings);
    m.yesNoWrong = yes.intersecting != !reference.empty() || yes.pairs.size() > 1 ||
                   (!yes.pairs.empty() &&
                    !std::binary_search(reference.begin(), reference.end(), yes.pairs[0]));
    settings.mode = QueryMode::kContacts;
    settings.descent = Descent::kFirstThenSecond;
    const QueryResult& contacts = query.run(a, pa, b, pb, settings);
    std::vector<TrianglePair> contactPairs;
    for (const PairContact& c : contacts.contacts) {
        contactPairs.push_back(c.pair);
        m.contactsWrong = m.contactsWrong || c.geometry.count == 0;
    }
    std::sort(contactPairs.begin(), contactPairs.end());
    m.contactsWrong = m.contactsWrong || contactPairs != reference;
    return m;
}

/// One pose class's outcome: how many poses collide (by the reference) and mismatches.
struct ClassTally {
    int poses = 0, colliding = 0, mismatches = 0;
};

/// Runs every configuration of `modelsA` x `modelsB` against the reference at every pose,
/// reporting the first few mismatches with the seed; returns per-class tallies.
inline std::map<workload::PoseClass, ClassTally> compareEverywhere(
    const workload::WorkloadMesh& meshA, const ModelSet& modelsA,
    const workload::WorkloadMesh& meshB, const ModelSet& modelsB, int posesPerClass,
    std::uint32_t seed, const std::vector<int>& leafSizes = {1, 2, 3, 4, 5, 6, 7, 8}) {
    std::map<workload::PoseClass, ClassTally> tally;
    const MeshModel& obbA = modelsA.get(TreeKind::kObb, 4);
    const MeshModel& obbB = modelsB.get(TreeKind::kObb, 4);
    MeshQuery query;
    int reported = 0;
    for (workload::PoseClass kind : workload::allPoseClasses()) {
        const bool exact =
            kind == workload::PoseClass::kCoincident || kind == workload::PoseClass::kShifted;
        if (exact && meshA.mesh != meshB.mesh) {
            continue;
        }
        const std::vector<workload::WorkloadPose> poses = workload::makePoses(
            meshA, obbA, meshB, obbB, kind, posesPerClass, seed + std::uint32_t(kind));
        // Two boxes have their own boxes as root OBBs (the fit keeps the model's axes where
        // they are tighter), so no pose parts them while their root OBBs overlap.
        const bool boxes = meshA.name.rfind("box-", 0) == 0 && meshB.name.rfind("box-", 0) == 0;
        const int expected = exact ? (kind == workload::PoseClass::kShifted ? 3 : 1)
                             : kind == workload::PoseClass::kApartObb && boxes ? 0
                                                                               : posesPerClass;
        EXPECT_EQ(int(poses.size()), expected)
            << meshA.name << " x " << meshB.name << " " << workload::poseClassName(kind);
        for (std::size_t p = 0; p < poses.size(); ++p) {
            const workload::WorkloadPose& pose = poses[p];
            const std::vector<TrianglePair> reference =
                referencePairs(*meshA.mesh, pose.a, *meshB.mesh, pose.b);
            ClassTally& t = tally[kind];
            ++t.poses;
            t.colliding += !reference.empty();
            for (TreeKind treeKind : allKinds()) {
                for (int leaf : leafSizes) {
                    const Mismatch m =
                        compareAtPose(modelsA.get(treeKind, leaf), pose.a,
                                      modelsB.get(treeKind, leaf), pose.b, reference, query);
                    if (m.any()) {
                        ++t.mismatches;
                        if (++reported <= 5) {
                            ADD_FAILURE()
                                << meshA.name << " x " << meshB.name << " "
                                << workload::poseClassName(kind) << " pose " << p << " (seed "
                                << seed + std::uint32_t(kind) << ") " << treeKindName(treeKind)
                                << " leaf " << leaf << ": " << m.missing << " missing, " << m.extra
                                << " extra of " << reference.size()
                                << (m.yesNoWrong ? ", yes/no wrong" : "")
                                << (m.contactsWrong ? ", contacts wrong" : "")
                                << "\n  A: " << describe(pose.a) << "\n  B: " << describe(pose.b);
                        }
                    }
                }
            }
        }
    }
    return tally;
}

/// The sample means something: each class collides as often as it should.
inline void expectMeaningfulClasses(const std::map<workload::PoseClass, ClassTally>& tally,
                                    const std::string& what) {
    using workload::PoseClass;
    for (const auto& [kind, t] : tally) {
        const double share = t.poses ? double(t.colliding) / t.poses : 0.0;
        const char* name = workload::poseClassName(kind);
        switch (kind) {
            case PoseClass::kDeep:
            case PoseClass::kShallow:
                EXPECT_GE(share, 0.75)
                    << what << " " << name << ": " << t.colliding << "/" << t.poses << " colliding";
                break;
            case PoseClass::kNear:
            case PoseClass::kApart:
            case PoseClass::kApartObb:
                EXPECT_LE(share, 0.25)
                    << what << " " << name << ": " << t.colliding << "/" << t.poses << " colliding";
                break;
            case PoseClass::kCoincident:
                EXPECT_EQ(t.colliding, t.poses) << what << " " << name;
                break;
            case PoseClass::kShifted:
                // A closed surface always meets its shifted copy; an open sheet shifted
                // along its normal may not.
                EXPECT_GE(t.colliding, 1) << what << " " << name;
                break;
        }
        EXPECT_EQ(t.mismatches, 0) << what << " " << name;
    }
}

}  // namespace kolize::narrowphase::testing
