//! The render node. OWNER: distributed helper.
