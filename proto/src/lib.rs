//! YAT's gRPC protocol. OWNER: distributed helper.
