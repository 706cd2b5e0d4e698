#pragma once
/// \file
/// The thesis's benchmark scenes (DIGEST section 7) as a pure broadphase stream: boxes of
/// turning, moving cubes (squares in 2D), one AABB per object per frame. Shared by the
/// benchmark programs and the tests.
///
/// - Space -halfSpace..+halfSpace on every axis (thesis: 500); every object a cube of edge
///   `cubeEdge` (2) with a random orientation that keeps turning, so its AABB changes size.
/// - Layout A (uniform): centres uniform in the space. Layout B (clustered): a fraction
///   `clusterFraction` (0.95) of the objects in a cube of edge `clusterEdge` (80) centred at
///   the origin, which they never leave; the rest uniform in the whole space.
/// - Motion: every object moves every frame with a constant random velocity of magnitude
///   speed x U(0.5, 1.5) (slow: 0.05, fast: 2 units per frame) and turns by
///   spin x U(0.5, 1.5) radians per frame about a random axis (slow: 0.01, fast: 0.1).
///   Objects reflect at the walls of their region (cluster or space), so they stay inside.
/// The same seed gives the same scene and the same trajectory.

#include <kolize/broadphase/aabb.h>

#include <cstdint>
#include <string>
#include <vector>

namespace kolize {

enum class ThesisLayout { Uniform, Clustered };
enum class ThesisMotion { Slow, Fast };

/// "A" / "B" and "slow" / "fast", as the reports print them.
const char* layoutName(ThesisLayout layout);
const char* motionName(ThesisMotion motion);

struct ThesisSceneSettings {
    ThesisLayout layout = ThesisLayout::Uniform;
    ThesisMotion motion = ThesisMotion::Slow;
    int objects = 1000;
    std::uint32_t seed = 1;
    double halfSpace = 500;         ///< the space is [-halfSpace, halfSpace]^D
    double cubeEdge = 2;            ///< edge of every cube
    double clusterEdge = 80;        ///< edge of the cluster cube of layout B
    double clusterFraction = 0.95;  ///< share of the objects inside the cluster in layout B
    double slowSpeed = 0.05;        ///< units per frame, slow motion
    double fastSpeed = 2;           ///< units per frame, fast motion
    double slowSpin = 0.01;         ///< radians per frame, slow motion
    double fastSpin = 0.1;          ///< radians per frame, fast motion
};

/// The moving objects of one thesis scene in D = 2 or 3 dimensions.
template <int D>
class ThesisScene {
  public:
    using Box = Aabb<D, double>;

    /// Throws std::invalid_argument for objects < 0 or a non-positive size.
    explicit ThesisScene(const ThesisSceneSettings& settings);

    /// Moves and turns every object by one frame and recomputes the boxes.
    void step();
    int size() const { return static_cast<int>(centres_.size()); }
    /// The current AABB of every object.
    const std::vector<Box>& boxes() const { return boxes_; }
    const ThesisSceneSettings& settings() const { return settings_; }

  private:
    using Vec = std::array<double, D>;
    /// Row-major D x D rotation matrix.
    using Rotation = std::array<double, D * D>;

    void updateBox(int object);

    ThesisSceneSettings settings_;
    std::vector<Vec> centres_;
    std::vector<Vec> velocities_;
    std::vector<double> walls_;          ///< half edge of each object's region
    std::vector<Rotation> orientation_;  ///< current orientation
    std::vector<Rotation> spin_;         ///< rotation applied every frame
    std::vector<Box> boxes_;
    int frame_ = 0;
};

extern template class ThesisScene<2>;
extern template class ThesisScene<3>;

}  // namespace kolize
