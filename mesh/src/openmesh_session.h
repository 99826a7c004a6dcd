#pragma once

#include <OpenMesh/Core/System/omstream.hh>

#include <mutex>

namespace csgrt::detail {

/// Held around every use of OpenMesh that may read files or print. OpenMesh's reader modules
/// keep per-read state in process-wide singletons, so reads are serialised; and its omerr,
/// omlog and omout streams print to the terminal, so they are disabled for the duration and
/// restored after. (Rerouting them with connect/disconnect is not an option: OpenMesh 9's
/// mostream::disconnect never frees what connect allocated.)
class OpenMeshSession {
public:
    OpenMeshSession()
        : lock_(mutex()),
          errors_(omerr().is_enabled()),
          log_(omlog().is_enabled()),
          out_(omout().is_enabled()) {
        omerr().disable();
        omlog().disable();
        omout().disable();
    }
    ~OpenMeshSession() {
        if (errors_) omerr().enable();
        if (log_) omlog().enable();
        if (out_) omout().enable();
    }
    OpenMeshSession(const OpenMeshSession&) = delete;
    OpenMeshSession& operator=(const OpenMeshSession&) = delete;

private:
    static std::mutex& mutex() {
        static std::mutex shared;
        return shared;
    }

    std::lock_guard<std::mutex> lock_;
    bool errors_, log_, out_;
};

}  // namespace csgrt::detail
