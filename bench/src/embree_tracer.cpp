#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "peers.h"

namespace csgrt::bench {

namespace {

/// Bytes the device holds, from Embree's memory monitor (called from its build threads).
struct MemoryTally {
    std::atomic<long long> current{0};
};

bool monitor(void* user, ssize_t bytes, bool /*post*/) {
    static_cast<MemoryTally*>(user)->current.fetch_add(bytes, std::memory_order_relaxed);
    return true;
}

void check(RTCDevice device, const char* step) {
    const RTCError code = rtcGetDeviceError(device);
    if (code != RTC_ERROR_NONE) {
        throw std::runtime_error(std::string("Embree: ") + step + " failed with error " +
                                 std::to_string(static_cast<int>(code)));
    }
}

class EmbreeTracer final : public Tracer {
public:
    EmbreeTracer(const TriangleSet<float>& set, bool robust, int build_threads,
                 EmbreeBuild* build, bool packets)
        : packets_(packets) {
        const std::string config = "threads=" + std::to_string(build_threads) + ",verbose=0";
        device_ = rtcNewDevice(config.c_str());
        if (device_ == nullptr) throw std::runtime_error("Embree: rtcNewDevice failed");
        rtcSetDeviceMemoryMonitorFunction(device_, monitor, &memory_);

        const auto start = std::chrono::steady_clock::now();
        scene_ = rtcNewScene(device_);
        if (robust) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
        RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        const std::size_t count = set.size();
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * count));
        auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), count));
        for (std::size_t i = 0; i < count; ++i) {
            for (int k = 0; k < 3; ++k) {
                const auto& corner = set.corner(i, k);
                float* vertex = vertices + 9 * i + 3 * k;
                vertex[0] = corner.x();
                vertex[1] = corner.y();
                vertex[2] = corner.z();
                indices[3 * i + k] = static_cast<unsigned>(3 * i + k);
            }
        }
        const long long buffers = memory_.current.load();
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene_, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene_);
        check(device_, "building the scene");
        if (build != nullptr) {
            build->build_milliseconds =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
            build->bytes = static_cast<std::size_t>(memory_.current.load());
            build->buffer_bytes = static_cast<std::size_t>(buffers);
        }
    }
    ~EmbreeTracer() override {
        if (scene_ != nullptr) rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
    }
    EmbreeTracer(const EmbreeTracer&) = delete;
    EmbreeTracer& operator=(const EmbreeTracer&) = delete;

    std::size_t nearest(std::span<const Ray> rays, QueryScratch&) const override {
        if (packets_) return nearest_packets(rays);
        return one_by_one(rays, [&](RTCIntersectContext& context, const Ray& ray) {
            RTCRayHit query;
            fill(ray, query.ray);
            query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scene_, &context, &query);
            return query.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        });
    }
    std::size_t occluded(std::span<const Ray> rays, QueryScratch&) const override {
        if (packets_) return occluded_packets(rays);
        return one_by_one(rays, [&](RTCIntersectContext& context, const Ray& ray) {
            RTCRay query;
            fill(ray, query);
            rtcOccluded1(scene_, &context, &query);
            // Embree marks an occluded ray by setting tfar to -inf.
            return query.tfar == -INFINITY;
        });
    }

private:
    /// Rays per packet: rtcIntersect8 / rtcOccluded8, the width of Embree's AVX2 packet kernels
    /// (this project's CPUs have AVX2; rtcIntersect16 runs them twice). Consecutive rays form a
    /// packet: for camera rays, eight neighbouring pixels of a row.
    static constexpr int kPacket = 8;

    /// The rays [begin, begin + lanes) of `rays` as a packet; `valid` gets -1 for those lanes
    /// and 0 for the rest.
    static void fill_packet(std::span<const Ray> rays, std::size_t begin, int lanes, RTCRay8& packet,
                            int* valid) {
        for (int l = 0; l < kPacket; ++l) {
            valid[l] = l < lanes ? -1 : 0;
            RTCRay single;
            if (l < lanes) {
                fill(rays[begin + l], single);
            } else {
                fill(Ray{}, single);
            }
            packet.org_x[l] = single.org_x;
            packet.org_y[l] = single.org_y;
            packet.org_z[l] = single.org_z;
            packet.dir_x[l] = single.dir_x;
            packet.dir_y[l] = single.dir_y;
            packet.dir_z[l] = single.dir_z;
            packet.tnear[l] = single.tnear;
            packet.tfar[l] = single.tfar;
            packet.time[l] = single.time;
            packet.mask[l] = single.mask;
            packet.id[l] = single.id;
            packet.flags[l] = single.flags;
        }
    }

    /// Traces `rays` one at a time, each with its own default context, by `trace(context, ray)`,
    /// which returns whether the ray hit; returns how many did.
    template <class Trace>
    static std::size_t one_by_one(std::span<const Ray> rays, const Trace& trace) {
        std::size_t hits = 0;
        for (const Ray& ray : rays) {
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            hits += trace(context, ray) ? 1 : 0;
        }
        return hits;
    }

    /// Traces `rays` in packets of kPacket consecutive rays, each with a coherent context and
    /// its lanes' valid flags set by fill_packet in `trace(context, valid, begin, lanes)`,
    /// which returns how many of the packet's rays hit; returns the sum.
    template <class Trace>
    static std::size_t in_packets(std::span<const Ray> rays, const Trace& trace) {
        std::size_t hits = 0;
        for (std::size_t begin = 0; begin < rays.size(); begin += kPacket) {
            const int lanes = static_cast<int>(std::min<std::size_t>(kPacket, rays.size() - begin));
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            alignas(32) int valid[kPacket];
            hits += trace(context, valid, begin, lanes);
        }
        return hits;
    }

    std::size_t nearest_packets(std::span<const Ray> rays) const {
        return in_packets(rays, [&](RTCIntersectContext& context, int* valid, std::size_t begin,
                                    int lanes) {
            alignas(32) RTCRayHit8 query;
            fill_packet(rays, begin, lanes, query.ray, valid);
            for (int l = 0; l < kPacket; ++l) {
                query.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
                query.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect8(valid, scene_, &context, &query);
            std::size_t hits = 0;
            for (int l = 0; l < lanes; ++l)
                hits += query.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
            return hits;
        });
    }

    std::size_t occluded_packets(std::span<const Ray> rays) const {
        return in_packets(rays, [&](RTCIntersectContext& context, int* valid, std::size_t begin,
                                    int lanes) {
            alignas(32) RTCRay8 query;
            fill_packet(rays, begin, lanes, query, valid);
            rtcOccluded8(valid, scene_, &context, &query);
            std::size_t hits = 0;
            // Embree marks an occluded ray by setting tfar to -inf.
            for (int l = 0; l < lanes; ++l) hits += query.tfar[l] == -INFINITY ? 1 : 0;
            return hits;
        });
    }

    static void fill(const Ray& ray, RTCRay& query) {
        query.org_x = static_cast<float>(ray.origin.x());
        query.org_y = static_cast<float>(ray.origin.y());
        query.org_z = static_cast<float>(ray.origin.z());
        query.dir_x = static_cast<float>(ray.direction.x());
        query.dir_y = static_cast<float>(ray.direction.y());
        query.dir_z = static_cast<float>(ray.direction.z());
        query.tnear = static_cast<float>(ray.t_min);
        query.tfar = static_cast<float>(ray.t_max);
        query.time = 0.0f;
        query.mask = 0xffffffffu;
        query.id = 0;
        query.flags = 0;
    }

    bool packets_ = false;
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    MemoryTally memory_;
};

}  // namespace

bool embree_available() {
    return true;
}

std::string embree_version() {
    return "Embree " RTC_VERSION_STRING;
}

std::unique_ptr<Tracer> make_embree_tracer(const TriangleSet<float>& set, bool robust,
                                           int build_threads, EmbreeBuild* build, bool packets) {
    return std::make_unique<EmbreeTracer>(set, robust, build_threads, build, packets);
}

}  // namespace csgrt::bench
