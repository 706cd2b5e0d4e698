#include <kolize/engine/pair_stream.h>
#include <kolize/engine/statistics.h>
#include <kolize/engine/store_only.h>

#include <kolize/kolize.h>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace kolize {

namespace {

constexpr char kMagic[8] = {'K', 'O', 'L', 'Z', 'P', 'S', '0', '1'};

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

class Writer {
  public:
    explicit Writer(std::uint8_t scalarBytes) : scalarBytes_(scalarBytes) {}
    template <class T>
    void put(T value) {
        const char* bytes = reinterpret_cast<const char*>(&value);
        data_.insert(data_.end(), bytes, bytes + sizeof(T));
    }
    void putScalar(double value) {
        if (scalarBytes_ == 4) {
            put(static_cast<float>(value));
        } else {
            put(value);
        }
    }
    const std::vector<char>& data() const { return data_; }

  private:
    std::uint8_t scalarBytes_;
    std::vector<char> data_;
};

class Reader {
  public:
    Reader(const std::string& path, std::vector<char> data) : path_(path), data_(std::move(data)) {}
    template <class T>
    T get() {
        if (offset_ + sizeof(T) > data_.size()) {
            fail("truncated at byte " + std::to_string(offset_));
        }
        T value;
        std::memcpy(&value, data_.data() + offset_, sizeof(T));
        offset_ += sizeof(T);
        return value;
    }
    double getScalar(std::uint8_t scalarBytes) {
        return scalarBytes == 4 ? static_cast<double>(get<float>()) : get<double>();
    }
    bool done() const { return offset_ == data_.size(); }
    std::size_t offset() const { return offset_; }
    [[noreturn]] void fail(const std::string& what) const {
        throw std::runtime_error("pair stream '" + path_ + "': " + what);
    }

  private:
    std::string path_;
    std::vector<char> data_;
    std::size_t offset_ = 0;
};

}  // namespace

std::size_t PairStream::frames() const {
    return static_cast<std::size_t>(
        std::count_if(events.begin(), events.end(),
                      [](const StreamEvent& e) { return e.op == StreamEvent::Op::EndFrame; }));
}

void PairStream::save(const std::string& path) const {
    Writer out(scalarBytes);
    for (char c : kMagic) {
        out.put(c);
    }
    out.put(scalarBytes);
    for (const StreamEvent& event : events) {
        out.put(static_cast<std::uint8_t>(event.op));
        if (event.op == StreamEvent::Op::EndFrame) {
            continue;
        }
        out.put(event.object);
        if (event.op == StreamEvent::Op::Create) {
            out.put(static_cast<std::int32_t>(event.group));
            out.put(static_cast<std::int32_t>(event.mask));
        }
        if (event.op != StreamEvent::Op::Destroy) {
            for (int axis = 0; axis < 3; ++axis) {
                out.putScalar(event.aabbMin[axis]);
            }
            for (int axis = 0; axis < 3; ++axis) {
                out.putScalar(event.aabbMax[axis]);
            }
        }
    }
    std::ofstream file(path, std::ios::binary);
    file.write(out.data().data(), static_cast<std::streamsize>(out.data().size()));
    if (!file) {
        throw std::runtime_error("pair stream '" + path + "': cannot write the file");
    }
}

PairStream PairStream::load(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        throw std::runtime_error("pair stream '" + path + "': cannot open the file");
    }
    std::vector<char> data((std::istreambuf_iterator<char>(file)),
                           std::istreambuf_iterator<char>());
    Reader in(path, std::move(data));
    for (char expected : kMagic) {
        if (in.get<char>() != expected) {
            in.fail("not a kolize pair stream (bad magic)");
        }
    }
    PairStream stream;
    stream.scalarBytes = in.get<std::uint8_t>();
    if (stream.scalarBytes != 4 && stream.scalarBytes != 8) {
        in.fail("unsupported coordinate size " + std::to_string(stream.scalarBytes));
    }
    std::vector<bool> alive;
    while (!in.done()) {
        const std::size_t at = in.offset();
        StreamEvent event;
        const auto op = in.get<std::uint8_t>();
        if (op < 1 || op > 4) {
            in.fail("unknown event " + std::to_string(op) + " at byte " + std::to_string(at));
        }
        event.op = static_cast<StreamEvent::Op>(op);
        if (event.op != StreamEvent::Op::EndFrame) {
            event.object = in.get<std::uint32_t>();
            if (event.op == StreamEvent::Op::Create) {
                if (event.object != alive.size()) {
                    in.fail("object " + std::to_string(event.object) +
                            " created out of order at byte " + std::to_string(at));
                }
                alive.push_back(true);
                event.group = in.get<std::int32_t>();
                event.mask = in.get<std::int32_t>();
            } else if (event.object >= alive.size() || !alive[event.object]) {
                in.fail("object " + std::to_string(event.object) +
                        " used before creation or after "
                        "destruction at byte " +
                        std::to_string(at));
            }
            if (event.op == StreamEvent::Op::Destroy) {
                alive[event.object] = false;
            } else {
                for (double& value : event.aabbMin) {
                    value = in.getScalar(stream.scalarBytes);
                }
                for (double& value : event.aabbMax) {
                    value = in.getScalar(stream.scalarBytes);
                }
            }
        }
        stream.events.push_back(event);
    }
    return stream;
}

RecordingBroadphase::RecordingBroadphase(btBroadphaseInterface& inner, PairStream& stream)
    : inner_(inner), stream_(stream) {
    stream_.scalarBytes = sizeof(btScalar);
}

namespace {

StreamEvent boxEvent(StreamEvent::Op op, std::uint32_t object, const btVector3& aabbMin,
                     const btVector3& aabbMax) {
    StreamEvent event;
    event.op = op;
    event.object = object;
    for (int axis = 0; axis < 3; ++axis) {
        event.aabbMin[axis] = aabbMin[axis];
        event.aabbMax[axis] = aabbMax[axis];
    }
    return event;
}

}  // namespace

btBroadphaseProxy* RecordingBroadphase::createProxy(const btVector3& aabbMin,
                                                    const btVector3& aabbMax, int shapeType,
                                                    void* userPtr, int collisionFilterGroup,
                                                    int collisionFilterMask,
                                                    btDispatcher* dispatcher) {
    btBroadphaseProxy* proxy =
        inner_.createProxy(aabbMin, aabbMax, shapeType, userPtr, collisionFilterGroup,
                           collisionFilterMask, dispatcher);
    StreamEvent event = boxEvent(StreamEvent::Op::Create, nextObject_, aabbMin, aabbMax);
    event.group = collisionFilterGroup;
    event.mask = collisionFilterMask;
    stream_.events.push_back(event);
    objectOf_[proxy] = nextObject_++;
    return proxy;
}

void RecordingBroadphase::destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
    StreamEvent event;
    event.op = StreamEvent::Op::Destroy;
    event.object = objectOf_.at(proxy);
    objectOf_.erase(proxy);
    stream_.events.push_back(event);
    inner_.destroyProxy(proxy, dispatcher);
}

void RecordingBroadphase::setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin,
                                  const btVector3& aabbMax, btDispatcher* dispatcher) {
    stream_.events.push_back(
        boxEvent(StreamEvent::Op::SetAabb, objectOf_.at(proxy), aabbMin, aabbMax));
    inner_.setAabb(proxy, aabbMin, aabbMax, dispatcher);
}

void RecordingBroadphase::calculateOverlappingPairs(btDispatcher* dispatcher) {
    inner_.calculateOverlappingPairs(dispatcher);
    stream_.events.push_back(StreamEvent{});
}

std::size_t ReplayResult::totalMissing() const {
    std::size_t total = 0;
    for (const ReplayFrame& frame : frames) {
        total += frame.missing;
    }
    return total;
}

std::size_t ReplayResult::totalExtra() const {
    std::size_t total = 0;
    for (const ReplayFrame& frame : frames) {
        total += frame.extra;
    }
    return total;
}

double ReplayResult::medianFrameSeconds() const {
    std::vector<double> times;
    for (const ReplayFrame& frame : frames) {
        times.push_back(frame.updateSeconds + frame.pairSeconds);
    }
    return median(times);
}

std::size_t ReplayResult::restingFrames() const {
    std::size_t count = 0;
    for (const ReplayFrame& frame : frames) {
        count += frame.changedProxies == 0 ? 1 : 0;
    }
    return count;
}

double ReplayResult::medianRestingSeconds() const {
    std::vector<double> times;
    for (const ReplayFrame& frame : frames) {
        if (frame.changedProxies == 0) {
            times.push_back(frame.updateSeconds + frame.pairSeconds);
        }
    }
    return times.empty() ? 0.0 : median(times);
}

namespace {

/// Per frame, the proxies created, destroyed or given a box that differs from their last one
/// (counted apart from the timed replay).
std::vector<std::size_t> changedProxiesPerFrame(const PairStream& stream) {
    std::vector<std::size_t> changed;
    std::vector<std::array<double, 6>> last;
    std::size_t count = 0;
    for (const StreamEvent& event : stream.events) {
        const std::array<double, 6> box = {event.aabbMin[0], event.aabbMin[1], event.aabbMin[2],
                                           event.aabbMax[0], event.aabbMax[1], event.aabbMax[2]};
        switch (event.op) {
            case StreamEvent::Op::Create:
                last.push_back(box);
                ++count;
                break;
            case StreamEvent::Op::Destroy:
                ++count;
                break;
            case StreamEvent::Op::SetAabb:
                count += last[event.object] == box ? 0 : 1;
                last[event.object] = box;
                break;
            case StreamEvent::Op::EndFrame:
                changed.push_back(count);
                count = 0;
                break;
        }
    }
    return changed;
}

}  // namespace

ReplayResult replay(const PairStream& stream, std::string_view name,
                    const BroadphaseSettings& settings) {
    std::unique_ptr<btBroadphaseInterface> broadphase = makeMeasuredBroadphase(name, settings);
    ReplayResult result;
    result.broadphase = std::string(name);
    std::vector<btBroadphaseProxy*> proxies;
    std::vector<ProxyBox> boxes;
    auto toVector = [](const double* v) {
        return btVector3(btScalar(v[0]), btScalar(v[1]), btScalar(v[2]));
    };
    const std::vector<std::size_t> changed = changedProxiesPerFrame(stream);
    ReplayFrame frame;
    Clock::time_point start = Clock::now();
    for (const StreamEvent& event : stream.events) {
        switch (event.op) {
            case StreamEvent::Op::Create:
                // Bullet's broadphases ignore proxies without a client object; any address will do.
                proxies.push_back(broadphase->createProxy(toVector(event.aabbMin),
                                                          toVector(event.aabbMax), 0, &proxies,
                                                          event.group, event.mask, nullptr));
                boxes.push_back(
                    ProxyBox{proxies.back(), toVector(event.aabbMin), toVector(event.aabbMax)});
                break;
            case StreamEvent::Op::Destroy:
                broadphase->destroyProxy(proxies[event.object], nullptr);
                proxies[event.object] = nullptr;
                break;
            case StreamEvent::Op::SetAabb:
                broadphase->setAabb(proxies[event.object], toVector(event.aabbMin),
                                    toVector(event.aabbMax), nullptr);
                boxes[event.object].aabbMin = toVector(event.aabbMin);
                boxes[event.object].aabbMax = toVector(event.aabbMax);
                break;
            case StreamEvent::Op::EndFrame: {
                frame.updateSeconds = secondsSince(start);
                const Clock::time_point pairStart = Clock::now();
                broadphase->calculateOverlappingPairs(nullptr);
                frame.pairSeconds = secondsSince(pairStart);

                std::vector<ProxyBox> live;
                for (std::size_t object = 0; object < proxies.size(); ++object) {
                    if (proxies[object] != nullptr) {
                        live.push_back(boxes[object]);
                    }
                }
                const btOverlappingPairCache* cache = broadphase->getOverlappingPairCache();
                const std::vector<UidPair> truth = exactPairs(live, cache);
                const std::vector<UidPair> reported = cachedPairs(*cache);
                const PairDifference difference = comparePairs(truth, reported);
                frame.truePairs = truth.size();
                frame.reportedPairs = reported.size();
                frame.missing = difference.missing.size();
                frame.extra = difference.extra.size();
                frame.changedProxies = changed[result.frames.size()];
                result.frames.push_back(frame);
                frame = ReplayFrame{};
                start = Clock::now();
                break;
            }
        }
    }
    return result;
}

}  // namespace kolize
