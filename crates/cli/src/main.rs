//! The `hocurve` command line: a thin layer over the hocurve crates that parses arguments,
//! runs the pipeline and prints a summary. Every error ends the program with exit code 1
//! and one line on stderr.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::NodeFamily;

/// Curved high-order meshes of arbitrary order from straight-sided meshes.
#[derive(Parser)]
#[command(name = "hocurve", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Turn a linear mesh into an order-P mesh and write it (.vtu for ParaView, .msh for Gmsh).
    ///
    /// For now only `--straight` is available: the order-P nodes are placed on the straight
    /// elements. Curving onto a geometry comes with `--geometry` in a later release.
    Curve {
        /// Linear input mesh (Gmsh MSH 4.1 or 2.2, ASCII or binary).
        mesh: PathBuf,
        /// Polynomial order P of the output mesh (1 = linear).
        #[arg(short = 'p', long, value_parser = clap::value_parser!(u32).range(1..=20))]
        order: u32,
        /// Nodal distribution on the reference elements: fekete, gll, warp-blend or
        /// equispaced. Output files always hold equispaced nodes (what VTK and Gmsh assume);
        /// the distribution decides where the mesh is sampled and, later, curved.
        #[arg(long, default_value = "fekete")]
        nodes: NodeFamily,
        /// Keep the elements straight-sided (no geometry, no curving).
        #[arg(long)]
        straight: bool,
        /// Output file: `.vtu` (VTK Lagrange cells) or `.msh` (Gmsh MSH 4.1, high order).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Print what a mesh file holds: dimension, vertices, cells by type, boundary groups.
    Info {
        /// Linear input mesh (Gmsh MSH 4.1 or 2.2, ASCII or binary).
        mesh: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hocurve: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Curve {
            mesh,
            order,
            nodes,
            straight,
            output,
        } => {
            if !straight {
                bail!("curving onto a geometry is not available yet; pass --straight to write the straight-sided order-{order} mesh");
            }
            let start = Instant::now();
            let linear = hocurve_io::read_msh(&mesh)?;
            let high_order = HighOrderMesh::from_linear(&linear, order as usize, nodes)
                .with_context(|| format!("{}", mesh.display()))?;
            hocurve_io::write_mesh(&output, &high_order)?;
            println!(
                "{}: {}D, {} cells, order {} ({} nodes): {} nodes, {} boundary facets -> {} ({:.2} s)",
                mesh.display(),
                high_order.dim,
                high_order.cells.len(),
                order,
                nodes,
                high_order.nodes.len(),
                high_order.facets.len(),
                output.display(),
                start.elapsed().as_secs_f64()
            );
            Ok(())
        }
        Command::Info { mesh } => {
            let linear = hocurve_io::read_msh(&mesh)?;
            println!("{}", mesh.display());
            println!("  dimension  {}", linear.dim);
            println!("  vertices   {}", linear.vertices.len());
            let mut by_type = std::collections::BTreeMap::new();
            for c in &linear.cells {
                *by_type.entry(c.kind).or_insert(0usize) += 1;
            }
            for (kind, n) in by_type {
                println!("  {:<10} {n}", kind.name());
            }
            for group in &linear.physical_groups {
                let count = linear
                    .facets
                    .iter()
                    .chain(&linear.cells)
                    .filter(|e| {
                        e.kind.dim() == group.dim
                            && linear
                                .physical_tags(group.dim, e.entity)
                                .contains(&group.tag)
                    })
                    .count();
                println!(
                    "  group {:>3} \"{}\" ({}D): {count} elements",
                    group.tag, group.name, group.dim
                );
            }
            Ok(())
        }
    }
}
