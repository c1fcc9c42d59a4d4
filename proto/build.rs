//! Compiles render.proto with protox (a pure-Rust protobuf compiler), so building needs no
//! system `protoc`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("cargo:rerun-if-changed=render.proto");
    let descriptors = protox::compile(["render.proto"], ["."])?;
    tonic_prost_build::configure()
        // Blob chunks and sample buffers are sliced and moved without copies.
        .bytes(".yat.render.v1")
        .compile_fds(descriptors)?;
    Ok(())
}
