//! `radiosity-mpi`: `radiosity formfactors`, `solve` and `render` with the form factors
//! computed across the ranks of an MPI job (`mpirun -np N radiosity-mpi formfactors ...`).
//!
//! Every rank reads and meshes the scene with the same flags as `radiosity` (the flags are
//! the `radiosity_cli` library's). Rank 0 deals row blocks to whichever rank asks
//! ([`radiosity_mpi::deal`]), computes blocks itself on a second thread, and writes each
//! block into the output as it arrives ([`FormFactorStreamWriter`]: the bytes of
//! `radiosity formfactors`, renamed into place only when every row is in) and, with
//! `--checkpoint DIR`, into the checkpoint directory. The blocks are those of
//! [`BlockComputer`], the library's own arithmetic: for the reciprocal methods each pair is
//! integrated once, in the upper triangle, and the writer mirrors it.
//!
//! A rank that fails sends what went wrong; rank 0 names the rank and its block and stops
//! the job. A rank that dies makes `mpirun` stop the job with SIGTERM: rank 0 then names
//! the blocks still out (with the rank of each) and removes its unfinished output.

#[macro_use]
extern crate radiosity_cli;

use std::io::IsTerminal;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use radiosity::form_factor::available_memory_bytes;
use radiosity::form_factor::{BlockComputer, RayCounter};
use radiosity::io::form_factor_file::FormFactorStreamWriter;
use radiosity::pipeline::Prepared;
use radiosity::solve::SolverKind;
use radiosity_cli::args::{
    FormFactorArgs, RenderArgs, SceneArgs, SolveArgs, SolveOptions, SolverArg,
};
use radiosity_cli::errors::describe;
use radiosity_cli::progress_bar::Reporter;
use radiosity_cli::setup;
use radiosity_cli::setup::DEFAULT_ADAPT_ROUNDS;
use radiosity_mpi::checkpoint::{Checkpoint, JobIdentity};
use radiosity_mpi::deal::{default_block_rows, Dealer};
use radiosity_mpi::wire::{self, Tag};

/// `radiosity` with the form factors computed across the ranks of an MPI job. Run it
/// under `mpirun -np N`; the output is byte for byte what `radiosity` writes with the same
/// flags.
#[derive(Parser)]
#[command(name = "radiosity-mpi", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Compute the form-factor matrix across the ranks and write it to a file, as
    /// `radiosity formfactors` does.
    Formfactors {
        #[command(flatten)]
        args: FormFactorArgs,
        #[command(flatten)]
        mpi: MpiArgs,
    },
    /// Compute the form factors across the ranks, then solve on rank 0 as `radiosity
    /// solve` does.
    Solve {
        #[command(flatten)]
        args: SolveArgs,
        #[command(flatten)]
        mpi: MpiArgs,
    },
    /// Compute the form factors across the ranks, then solve and render on rank 0 as
    /// `radiosity render` does.
    Render {
        #[command(flatten)]
        args: RenderArgs,
        #[command(flatten)]
        mpi: MpiArgs,
    },
}

/// The flags of the distributed computation.
#[derive(Args, Clone)]
struct MpiArgs {
    /// Write every finished row block to DIR as it completes (with a manifest naming the
    /// scene, mesh and method), so that a killed job can be resumed with --resume.
    #[arg(long, value_name = "DIR")]
    checkpoint: Option<PathBuf>,
    /// Continue the job whose finished blocks are in --checkpoint DIR: compute only the
    /// rows they lack. Refused when DIR is another scene's, mesh's or method's.
    #[arg(long, requires = "checkpoint")]
    resume: bool,
    /// Rows per block dealt to a rank (default: about eight blocks a rank, at most 256).
    #[arg(long, value_name = "N", value_parser = parse_block_rows)]
    block_rows: Option<u64>,
}

/// `--block-rows`: a whole number of at least 1, in the words of `radiosity`'s own
/// parsers (review of issue #16: `-1` was told "at least 0", 0 being refused too).
fn parse_block_rows(text: &str) -> Result<u64, String> {
    match text.trim().parse::<u64>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err("give a whole number of at least 1".to_string()),
    }
}

fn main() -> ExitCode {
    let Some((universe, _)) = mpi::initialize_with_threading(mpi::Threading::Funneled) else {
        errln!("error: radiosity-mpi could not initialise MPI (run it under mpirun)");
        return ExitCode::FAILURE;
    };
    let world = universe.world();
    let rank = world.rank();
    // Negative numbers are values, as for `radiosity` (QA of issue #16: `--epsilon -1` was
    // "unexpected argument '-1'" here).
    let matches = radiosity_cli::args::negative_numbers(Cli::command()).try_get_matches();
    let cli = match matches.and_then(|m| Cli::from_arg_matches(&m)) {
        Ok(cli) => cli,
        Err(e) => {
            // Every rank parses the same flags; one copy of the message is enough. A wrong
            // value in the frame and exit status of `radiosity`'s (QA of issue #16).
            if let Some(line) = radiosity_cli::args::value_error(&e) {
                if rank == 0 {
                    errln!("error: {line}");
                }
                return ExitCode::FAILURE;
            }
            if rank == 0 {
                let _ = e.print();
            }
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    radiosity::io::protect_inputs();
    let result = if rank == 0 {
        lead(&world, cli)
    } else {
        follow(&world, cli)
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            errln!("{}", describe(&err));
            ExitCode::FAILURE
        }
    }
}

/// The scene's flags of a command.
fn scene_args(command: &Command) -> &SceneArgs {
    match command {
        Command::Formfactors { args, .. } => &args.scene,
        Command::Solve { args, .. } => &args.scene,
        Command::Render { args, .. } => &args.scene,
    }
}

/// Whether rank 0 computes the form factors of `solve` or `render` across the ranks, and
/// with which solver: only a dense solver (LU, Gauss-Seidel) takes a matrix, and not when it
/// is read from a file or adaptive subdivision computes matrices of its own meshes. `auto`
/// is resolved here as `radiosity` resolves it (from the element count and the memory of
/// rank 0), since the solve is then given the matrix as a file, with which `auto` means
/// Gauss-Seidel.
fn dense_solver(scene: &SceneArgs, options: &SolveOptions) -> Result<Option<SolverKind>> {
    let quiet = Reporter::new(true);
    let (prepared, _, solver) = setup::prepare_solve(scene, options, &quiet)?;
    if !solver.needs_matrix()
        || options.form_factors.is_some()
        || options.adapt_rounds.unwrap_or(DEFAULT_ADAPT_ROUNDS) > 0
    {
        return Ok(None);
    }
    Ok(Some(match options.solver.0 {
        SolverKind::Auto => {
            radiosity::solve::choose(prepared.mesh.len(), available_memory_bytes()).kind()
        }
        kind => kind,
    }))
}

/// Rank 0 tells every rank whether form factors are dealt: 1 yes, 0 no (rank 0 runs the
/// command alone, or stops on an error).
fn broadcast_decision(world: &SimpleCommunicator, deal: bool) -> bool {
    let mut flag = deal as u8;
    world.process_at_rank(0).broadcast_into(&mut flag);
    flag == 1
}

/// The command's outputs and the flags that need no scene, checked on rank 0 before any
/// rank reads the scene, by the same code as `radiosity`'s (QA of issue #16: `-o x.txt`,
/// `-o nowhere/x.ff` or `-o` the scene itself were found only after every rank had read and
/// meshed the scene, or after the whole job). Returns the form-factor output of
/// `formfactors`.
fn check_outputs(command: &Command) -> Result<Option<PathBuf>> {
    Ok(match command {
        Command::Formfactors { args, .. } => {
            Some(radiosity_cli::commands::formfactors::output(args)?)
        }
        Command::Solve { args, .. } => {
            radiosity_cli::commands::solve::outputs(args)?;
            None
        }
        Command::Render { args, .. } => {
            radiosity_cli::commands::render::check(args)?;
            None
        }
    })
}

/// Rank 0: prepare, deal and write the form factors, then run the rest of the command.
fn lead(world: &SimpleCommunicator, cli: Cli) -> Result<()> {
    let reporter = Reporter::new(scene_args(&cli.command).quiet);
    let alone = "radiosity-mpi: this solve takes no matrix of form factors (its solver computes \
                 its own, it reads them from a file, or adaptive subdivision remeshes): rank 0 \
                 runs it alone";
    // A refused output stops every rank before any reads the scene: they are told that no
    // form factors are dealt, and end.
    let output = match check_outputs(&cli.command) {
        Ok(output) => output,
        Err(err) => {
            broadcast_decision(world, false);
            return Err(err);
        }
    };
    match cli.command {
        Command::Formfactors { args, mpi } => {
            broadcast_decision(world, true);
            let output = output.expect("formfactors has an output");
            deal_form_factors(world, &args.scene, &mpi, &output, &reporter)?;
            reporter.print_timings();
            Ok(())
        }
        Command::Solve { mut args, mpi } => {
            let kind = dense_solver(&args.scene, &args.solve);
            if !broadcast_decision(world, matches!(kind, Ok(Some(_)))) {
                kind?;
                reporter.note(alone);
                return radiosity_cli::commands::solve::run(args);
            }
            let ff = scratch_file(args.output.as_deref())?;
            deal_form_factors(world, &args.scene, &mpi, &ff, &reporter)?;
            args.solve.solver = SolverArg(kind?.expect("dealt for a dense solver"));
            args.solve.form_factors = Some(ff.to_path_buf());
            let result = radiosity_cli::commands::solve::run(args);
            radiosity::io::release_input(&ff);
            result
        }
        Command::Render { mut args, mpi } => {
            let kind = dense_solver(&args.scene, &args.solve);
            if !broadcast_decision(world, matches!(kind, Ok(Some(_)))) {
                kind?;
                reporter.note(alone);
                return radiosity_cli::commands::render::run(args);
            }
            let ff = scratch_file(args.output.as_deref())?;
            deal_form_factors(world, &args.scene, &mpi, &ff, &reporter)?;
            args.solve.solver = SolverArg(kind?.expect("dealt for a dense solver"));
            args.solve.form_factors = Some(ff.to_path_buf());
            let result = radiosity_cli::commands::render::run(args);
            radiosity::io::release_input(&ff);
            result
        }
    }
}

/// A temporary form-factor file beside `output` (the current directory without one),
/// removed when dropped.
fn scratch_file(output: Option<&Path>) -> Result<tempfile::TempPath> {
    let dir = match output.and_then(Path::parent) {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok(tempfile::Builder::new()
        .prefix(".radiosity-mpi.")
        .suffix(".ff")
        .tempfile_in(&dir)
        .with_context(|| {
            format!(
                "cannot make a temporary form-factor file in {}",
                dir.display()
            )
        })?
        .into_temp_path())
}

/// The other ranks: compute the blocks rank 0 deals, if the command distributes any.
fn follow(world: &SimpleCommunicator, cli: Cli) -> Result<()> {
    if !broadcast_decision(world, false) {
        return Ok(());
    }
    let scene_args = scene_args(&cli.command);
    let root = world.process_at_rank(0);
    let quiet = Reporter::new(true);
    let prepared = match setup::prepare_scene(scene_args, &quiet) {
        Ok((prepared, _)) => prepared,
        Err(err) => {
            let text = format!("cannot prepare the scene: {}", describe(&err));
            root.send_with_tag(text.as_bytes(), Tag::Failed as i32);
            // Wait for rank 0 to stop the job, so that its message comes out.
            let _ = root.receive_vec::<u8>();
            bail!("rank {}: {text}", world.rank());
        }
    };
    let ctx = prepared.context();
    let computer = BlockComputer::new(&ctx, prepared.method());
    let fault = test_fault(world.rank());
    root.send_with_tag(
        &wire::ready(prepared.fingerprint(), prepared.mesh.len())[..],
        Tag::Ready as i32,
    );
    let mut blocks = 0usize;
    loop {
        let (bytes, status) = root.receive_vec::<u8>();
        match Tag::from_i32(status.tag()) {
            Some(Tag::Stop) => return Ok(()),
            Some(Tag::Assign) => {}
            _ => bail!("rank {}: unexpected message {}", world.rank(), status.tag()),
        }
        let rows = wire::read_assign(&bytes)?;
        if fault.is_some_and(|after| blocks == after) {
            // RADIOSITY_MPI_TEST_EXIT: die without a word, as a crashed node would.
            std::process::exit(3);
        }
        let rays = RayCounter::default();
        let block = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            computer.block(rows.clone(), &rays)
        }));
        match block {
            Ok(block) => {
                let message = wire::result(
                    &block.rows,
                    rays.get(),
                    &block.data,
                    computer.n(),
                    computer.upper_only(),
                );
                drop(block);
                root.send_with_tag(&message[..], Tag::Result as i32);
                blocks += 1;
            }
            Err(panic) => {
                let what = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "a panic".into());
                let text = format!("rows {}..{}: {what}", rows.start, rows.end);
                root.send_with_tag(text.as_bytes(), Tag::Failed as i32);
                let _ = root.receive_vec::<u8>();
                bail!("rank {} failed on {text}", world.rank());
            }
        }
    }
}

/// `RADIOSITY_MPI_TEST_EXIT=RANK:BLOCKS`: rank RANK exits (status 3, no message, no MPI
/// finalisation) when dealt its block number BLOCKS + 1, as a rank whose node dies: for the
/// tests of the failure path, which need a rank to die at a known point.
fn test_fault(rank: i32) -> Option<usize> {
    let spec = std::env::var("RADIOSITY_MPI_TEST_EXIT").ok()?;
    let (r, blocks) = spec.split_once(':')?;
    (r.trim().parse::<i32>().ok()? == rank).then(|| blocks.trim().parse().ok())?
}

/// What rank 0 keeps while a job runs.
struct Job<'a> {
    prepared: &'a Prepared,
    dealer: Dealer,
    writer: Option<FormFactorStreamWriter>,
    checkpoint: Option<Checkpoint>,
    output: &'a Path,
    progress: Progress,
    rays: u64,
    blocks_by_rank: Vec<usize>,
}

impl Job<'_> {
    /// Writes a finished block into the output and the checkpoint.
    fn take(&mut self, rank: usize, rows: Range<usize>, rays: u64, data: &[f32]) -> Result<()> {
        match self.dealer.held_by(rank) {
            Some(held) if *held == rows => {}
            held => bail!(
                "rank {rank} returned rows {}..{}, but holds {:?}",
                rows.start,
                rows.end,
                held
            ),
        }
        // The stage boundary of `radiosity formfactors` (FormFactorMatrix::check_entries):
        // no NaN, infinity or negative entry is written.
        let n = self.prepared.mesh.len();
        for (k, row) in data.chunks(n.max(1)).enumerate() {
            radiosity::form_factor::check_row(rows.start + k, row.iter().map(|&f| f as f64))
                .map_err(|e| anyhow!("rank {rank}, rows {}..{}: {e}", rows.start, rows.end))?;
        }
        let writer = self
            .writer
            .as_mut()
            .expect("the writer lives until the end");
        writer
            .write_block(rows.clone(), data)
            .with_context(|| format!("cannot write {}", self.output.display()))?;
        if let Some(cp) = &self.checkpoint {
            cp.save(&rows, data)?;
        }
        self.dealer.finish(rank);
        self.rays += rays;
        self.blocks_by_rank[rank] += 1;
        self.progress.block_done(rows.len(), &self.dealer);
        Ok(())
    }

    /// The message for a job stopped from outside: the blocks still out, by rank.
    fn stopped_message(&self) -> String {
        let held: Vec<String> = self
            .dealer
            .held()
            .map(|(r, b)| format!("rank {r} had rows {}..{}", b.start, b.end))
            .collect();
        let kept = match &self.checkpoint {
            Some(cp) => format!(
                "; checkpoint {} keeps the {} finished blocks: run the same command with \
                 --resume to continue",
                cp.dir().display(),
                self.dealer.done()
            ),
            None => String::new(),
        };
        format!(
            "error: the job was stopped (SIGTERM: mpirun stops every rank when one fails or \
             its node disappears; its message names the rank) with {} of {} row blocks done; \
             unfinished: {}; {} was not written{kept}",
            self.dealer.done(),
            self.dealer.total(),
            if held.is_empty() {
                "none".to_string()
            } else {
                held.join(", ")
            },
            self.output.display()
        )
    }
}

/// One progress display for the whole job on rank 0: a bar on a terminal, else a line at
/// most every 2 s; blocks done of total and rows per second.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    lines: bool,
    start: Instant,
    last_line: Instant,
    rows: usize,
}

impl Progress {
    fn new(quiet: bool, dealer: &Dealer) -> Progress {
        let terminal = std::io::stderr().is_terminal();
        let bar = (!quiet && terminal).then(|| {
            let bar = indicatif::ProgressBar::new(dealer.total() as u64);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "form factors [{bar:30}] {pos}/{len} blocks, {msg}, {elapsed}",
                )
                .expect("a valid template")
                .progress_chars("=> "),
            );
            bar.set_position(dealer.done() as u64);
            bar
        });
        Progress {
            bar,
            lines: !quiet && !terminal,
            start: Instant::now(),
            last_line: Instant::now(),
            rows: 0,
        }
    }

    fn block_done(&mut self, rows: usize, dealer: &Dealer) {
        self.rows += rows;
        let rate = self.rows as f64 / self.start.elapsed().as_secs_f64().max(1e-9);
        if let Some(bar) = &self.bar {
            bar.set_position(dealer.done() as u64);
            bar.set_message(format!("{rate:.1} rows/s"));
        } else if self.lines
            && (self.last_line.elapsed() >= Duration::from_secs(2) || dealer.is_done())
        {
            self.last_line = Instant::now();
            errln!(
                "form factors: {}/{} blocks, {rate:.1} rows/s",
                dealer.done(),
                dealer.total()
            );
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// Rank 0's part of a distributed form-factor computation: prepare the scene, check every
/// rank's mesh, deal the blocks (computing some itself), write `output`.
fn deal_form_factors(
    world: &SimpleCommunicator,
    scene: &SceneArgs,
    mpi: &MpiArgs,
    output: &Path,
    reporter: &Reporter,
) -> Result<()> {
    let mut stopped = vec![false; world.size() as usize];
    let prepared = match prepare_lead(scene, reporter) {
        Ok(p) => p,
        Err(err) => {
            stop_all(world, &mut stopped);
            return Err(err);
        }
    };
    match run_job(world, &prepared, scene, mpi, output, reporter, &mut stopped) {
        Ok(()) => Ok(()),
        Err(err) => {
            stop_all(world, &mut stopped);
            Err(err)
        }
    }
}

/// [`setup::prepare_scene`] with the work limit and the notes of `radiosity formfactors`.
fn prepare_lead(scene: &SceneArgs, reporter: &Reporter) -> Result<Prepared> {
    let (prepared, stem) = setup::prepare_scene(scene, reporter)?;
    if !scene.no_work_limit {
        prepared.check_work()?;
    }
    setup::note_scene(&prepared, &stem, reporter);
    reporter.note(&format!(
        "form factors by {}; occlusion: {}",
        prepared.method(),
        prepared.method().occlusion()
    ));
    Ok(prepared)
}

/// Answers every other rank's next message with Stop (a rank computing a block finishes it
/// first; one that failed is waiting for this), so that every rank ends and finalises.
fn stop_all(world: &SimpleCommunicator, stopped: &mut [bool]) {
    stopped[0] = true;
    while let Some(r) = stopped.iter().position(|s| !s) {
        let (_, status) = world.process_at_rank(r as i32).receive_vec::<u8>();
        let _ = status;
        world
            .process_at_rank(r as i32)
            .send_with_tag(&[0u8; 0][..], Tag::Stop as i32);
        stopped[r] = true;
    }
}

fn run_job(
    world: &SimpleCommunicator,
    prepared: &Prepared,
    scene: &SceneArgs,
    mpi: &MpiArgs,
    output: &Path,
    reporter: &Reporter,
    stopped_ranks: &mut [bool],
) -> Result<()> {
    let ranks = world.size() as usize;
    let n = prepared.mesh.len();
    let method = prepared.method();
    let identity = JobIdentity {
        scene: scene
            .scene
            .as_deref()
            .map_or("the built-in Cornell box".into(), |p| {
                p.display().to_string()
            }),
        elements: n,
        fingerprint: prepared.fingerprint(),
        method: method.to_string(),
    };
    let (checkpoint, found) = match &mpi.checkpoint {
        Some(dir) => {
            let (cp, found) =
                Checkpoint::open(dir, &identity, mpi.resume).map_err(|e| match e {
                    e @ radiosity_mpi::checkpoint::CheckpointError::NotEmpty { .. } => anyhow!(e)
                        .context(
                            "add --resume to continue that job, or give --checkpoint an \
                             empty or new directory",
                        ),
                    e => anyhow!(e),
                })?;
            for (path, why) in &found.refused {
                reporter.note(&format!(
                    "checkpoint block {} not used ({why}): its rows are computed again",
                    path.display()
                ));
            }
            (Some(cp), found.blocks)
        }
        None => (None, Vec::new()),
    };
    let start = Instant::now();
    let ctx = prepared.context();
    let computer = BlockComputer::new(&ctx, method);
    let areas = computer.upper_only().then(|| prepared.areas());
    let writer = FormFactorStreamWriter::create(
        output,
        n,
        prepared.fingerprint(),
        &method.to_string(),
        areas,
    )
    .with_context(|| format!("cannot write {}", output.display()))?;
    let block_rows = mpi
        .block_rows
        .map_or_else(|| default_block_rows(n, ranks), |b| b as usize);
    let dealer = Dealer::new(n, block_rows, &found);
    let mut job = Job {
        prepared,
        progress: Progress::new(scene.quiet, &dealer),
        dealer,
        writer: Some(writer),
        checkpoint,
        output,
        rays: 0,
        blocks_by_rank: vec![0; ranks],
    };
    if !found.is_empty() {
        let cp = job
            .checkpoint
            .as_ref()
            .expect("blocks come from a checkpoint");
        let rows: usize = found.iter().map(|b| b.len()).sum();
        for b in &found {
            let data = cp
                .load(b)
                .map_err(|why| anyhow!("checkpoint block {}..{}: {why}", b.start, b.end))?;
            job.writer
                .as_mut()
                .expect("the writer")
                .write_block(b.clone(), &data)
                .with_context(|| format!("cannot write {}", output.display()))?;
        }
        reporter.note(&format!(
            "resumed from {}: {} blocks ({rows} of {n} rows) were done",
            cp.dir().display(),
            found.len()
        ));
    }
    reporter.note(&format!(
        "{} row blocks of up to {block_rows} rows over {ranks} ranks{}",
        job.dealer.total() - job.dealer.done(),
        if computer.upper_only() {
            " (upper triangle: each pair once)"
        } else {
            ""
        }
    ));

    // SIGTERM (mpirun stopping the job) sets this flag; the loop below says what was out.
    let stopped = Arc::new(AtomicBool::new(false));
    let sig = signal_hook::flag::register(signal_hook::consts::SIGTERM, Arc::clone(&stopped))
        .context("cannot watch for SIGTERM")?;

    let result = std::thread::scope(|scope| -> Result<()> {
        // Rank 0 computes blocks too, on its own thread (which makes no MPI call).
        let (to_local, local_rx) = mpsc::channel::<Range<usize>>();
        let (local_tx, from_local) =
            mpsc::channel::<(Range<usize>, u64, Result<Vec<f32>, String>)>();
        let computer = &computer;
        scope.spawn(move || {
            for rows in local_rx {
                let rays = RayCounter::default();
                let block = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    computer.block(rows.clone(), &rays)
                }));
                let block = block.map(|b| b.data).map_err(|p| {
                    p.downcast_ref::<String>()
                        .cloned()
                        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_else(|| "a panic".into())
                });
                if local_tx.send((rows, rays.get(), block)).is_err() {
                    break;
                }
            }
        });
        let mut local_busy = false;
        if let Some(rows) = job.dealer.deal(0) {
            to_local.send(rows).expect("the local thread runs");
            local_busy = true;
        }
        let stop = |stopped: &mut [bool], rank: usize| {
            world
                .process_at_rank(rank as i32)
                .send_with_tag(&[0u8; 0][..], Tag::Stop as i32);
            stopped[rank] = true;
        };
        while stopped_ranks[1..].iter().any(|s| !s) || !job.dealer.is_done() {
            if stopped.load(Ordering::Relaxed) {
                errln!("{}", job.stopped_message());
                // The unfinished output is removed; the checkpoint's blocks stay. Exit at
                // once: mpirun kills what is left of the job anyway.
                drop(job.writer.take());
                std::process::exit(1);
            }
            let mut idle = true;
            if let Some(probed) = world.any_process().immediate_matched_probe() {
                idle = false;
                let (bytes, status) = probed.matched_receive_vec::<u8>();
                let rank = status.source_rank() as usize;
                let peer = world.process_at_rank(rank as i32);
                match Tag::from_i32(status.tag()) {
                    Some(Tag::Ready) => {
                        let (fingerprint, elements) = wire::read_ready(&bytes)?;
                        if (fingerprint, elements) != (prepared.fingerprint(), n) {
                            // This rank stops below; the others are stopped by the caller.
                            stop(stopped_ranks, rank);
                            bail!(
                                "rank {rank} meshed the scene differently ({elements} elements, \
                                 fingerprint {fingerprint:016x}; rank 0 has {n}, {:016x}): \
                                 another scene file or another program version on its host",
                                prepared.fingerprint()
                            );
                        }
                    }
                    Some(Tag::Result) => {
                        let (rows, rays, data) =
                            wire::read_result(&bytes, n, computer.upper_only())?;
                        drop(bytes);
                        job.take(rank, rows, rays, &data)?;
                    }
                    Some(Tag::Failed) => {
                        let text = String::from_utf8_lossy(&bytes).into_owned();
                        stop(stopped_ranks, rank);
                        let block = job
                            .dealer
                            .held_by(rank)
                            .map_or("before its first block".into(), |b| {
                                format!("on rows {}..{}", b.start, b.end)
                            });
                        bail!("rank {rank} failed {block}: {text}");
                    }
                    _ => bail!(
                        "rank {rank} sent an unexpected message (tag {})",
                        status.tag()
                    ),
                }
                match job.dealer.deal(rank) {
                    Some(rows) => peer.send_with_tag(&wire::assign(&rows)[..], Tag::Assign as i32),
                    None => stop(stopped_ranks, rank),
                }
            }
            if local_busy {
                if let Ok((rows, rays, block)) = from_local.try_recv() {
                    idle = false;
                    local_busy = false;
                    let data = block.map_err(|what| {
                        anyhow!("rank 0 failed on rows {}..{}: {what}", rows.start, rows.end)
                    })?;
                    job.take(0, rows, rays, &data)?;
                    if let Some(rows) = job.dealer.deal(0) {
                        to_local.send(rows).expect("the local thread runs");
                        local_busy = true;
                    }
                }
            }
            if idle {
                std::thread::sleep(Duration::from_micros(200));
            }
        }
        Ok(())
    });
    signal_hook::low_level::unregister(sig);
    result?;
    job.progress.finish();
    let writer = job.writer.take().expect("the writer");
    radiosity::progress::run_stage(reporter, radiosity::progress::Stage::Write, 0, || {
        writer.finish()
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    let seconds = start.elapsed().as_secs_f64();
    reporter.note(&format!(
        "form factors: {n} rows in {seconds:.2} s ({:.1} rows/s) over {ranks} ranks, blocks \
         per rank {:?}; {:.3e} visibility rays",
        job.progress.rows as f64 / seconds.max(1e-9),
        job.blocks_by_rank,
        job.rays as f64
    ));
    reporter.note(&format!(
        "wrote {} ({n} x {n} form factors, method {method})",
        output.display()
    ));
    Ok(())
}
