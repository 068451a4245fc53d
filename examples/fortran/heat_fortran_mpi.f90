!> heat_fortran_mpi: heat_fortran's simulation on MPI ranks, instrumented through the `insitu_mpi`
!> and `insitu` modules.
!>
!>   mpiexec -n RANKS heat_fortran_mpi ARCHIVE [STEPS]
!>
!> The same heat equation as heat_fortran (three hot spots held at 1 in a unit cube of 32^3
!> samples, cold walls), cut into slabs along z: rank r owns a contiguous range of z planes
!> (32 / RANKS of them, the first 32 mod RANKS ranks one more) and holds one ghost layer on every
!> side. The x and y ghosts, and the z ghosts of the first and last slab, are the cold walls; the
!> other z ghosts are the neighbours' planes, exchanged with MPI_Sendrecv after every step. Each
!> rank evaluates the same stencil on the same values as the serial run, so the field is the
!> serial run's at every step, whatever the number of ranks.
!>
!> Every rank hands its slab (with its ghost layers) to the distributed instrument with
!> insitu_add_block; the configuration (written by rank 0 to ARCHIVE.json) keeps every 10th step,
!> and rank 0 writes the archive. Exits 0 when every call succeeded on every rank, 1 when any
!> failed (the run still goes to the end), 2 for bad arguments.
program heat_fortran_mpi
    use, intrinsic :: iso_c_binding, only: c_double, c_int
    use, intrinsic :: iso_fortran_env, only: error_unit
    use mpi
    use insitu
    use insitu_mpi
    implicit none

    integer, parameter :: n = 32       ! interior samples per axis, whole domain
    integer, parameter :: ghosts = 1   ! ghost layers on each side
    ! Hot spots: centre (global interior sample coordinates, from 0) and radius in samples.
    real(c_double), parameter :: spots(4, 3) = reshape([9.0d0, 10.0d0, 12.0d0, 3.0d0, &
                                                        22.0d0, 20.0d0, 16.0d0, 4.0d0, &
                                                        14.0d0, 24.0d0, 23.0d0, 2.5d0], [4, 3])
    ! alpha dt / dx^2 of explicit Euler; at most 1/6 in 3D for stability.
    real(c_double), parameter :: diffusion_number = 0.15d0

    ! This rank's slab, temperature(i, j, k) with i (x) fastest, as in heat_fortran: planes
    ! 1..nz_local are global planes z_first..z_first + nz_local - 1; 0 and nz_local + 1 are ghosts.
    real(c_double), allocatable :: temperature(:, :, :)
    real(c_double), allocatable :: next(:, :, :)
    type(insitu_instrument) :: instrument
    character(len=4096) :: archive, argument
    character(len=:), allocatable :: config_path
    real(c_double) :: spacing, dt
    integer(c_int) :: status
    integer :: rank, ranks, below, above, nz_local, z_first, ierror
    integer :: steps, step, failures, any_failures, stored, argument_count, io_status

    call MPI_Init(ierror)
    call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierror)
    call MPI_Comm_size(MPI_COMM_WORLD, ranks, ierror)

    argument_count = command_argument_count()
    if (argument_count < 1 .or. argument_count > 2) then
        if (rank == 0) write (error_unit, '(a)') "usage: heat_fortran_mpi ARCHIVE [STEPS]"
        call finish(2)
    end if
    call get_command_argument(1, archive)
    steps = 40
    if (argument_count == 2) then
        call get_command_argument(2, argument)
        read (argument, *, iostat=io_status) steps
        if (io_status /= 0 .or. steps < 1) then
            if (rank == 0) write (error_unit, '(3a)') "heat_fortran_mpi: STEPS = ", &
                trim(argument), " is not a positive integer"
            call finish(2)
        end if
    end if
    if (ranks > n) then
        if (rank == 0) write (error_unit, '(a, i0, a)') "heat_fortran_mpi: at most ", n, &
            " ranks (one z plane each)"
        call finish(2)
    end if

    ! Slabs along z; MPI_PROC_NULL beyond the walls, where MPI_Sendrecv leaves the ghosts at 0.
    nz_local = n / ranks
    z_first = rank * nz_local + min(rank, mod(n, ranks))
    if (rank < mod(n, ranks)) nz_local = nz_local + 1
    below = rank - 1
    above = rank + 1
    if (rank == 0) below = MPI_PROC_NULL
    if (rank == ranks - 1) above = MPI_PROC_NULL

    config_path = trim(archive)//".json"
    if (rank == 0) call write_config(config_path, trim(archive))
    call MPI_Barrier(MPI_COMM_WORLD, ierror)  ! the file is written before any rank reads it
    status = insitu_create_mpi(config_path, MPI_COMM_WORLD, instrument)
    if (status /= INSITU_OK) then
        ! Start-up fails alike on every rank (a bad configuration, no device); rank 0 says why.
        if (rank == 0) write (error_unit, '(4a)') "heat_fortran_mpi: ", &
            insitu_status_name(status), ": ", insitu_last_error()
        call finish(1)
    end if

    allocate (temperature(0:n + 1, 0:n + 1, 0:nz_local + 1), &
              next(0:n + 1, 0:n + 1, 0:nz_local + 1))
    temperature = 0.0d0
    next = 0.0d0
    spacing = 1.0d0 / n
    dt = diffusion_number * spacing**2  ! diffusivity 1 world unit^2 per unit time
    call apply_sources(temperature)
    call exchange_halos(temperature)

    failures = 0
    stored = 0
    do step = 1, steps
        ! 7-point Laplacian on the interior, the ghost planes as the serial run's neighbours.
        next(1:n, 1:n, 1:nz_local) = temperature(1:n, 1:n, 1:nz_local) + diffusion_number * ( &
            temperature(0:n - 1, 1:n, 1:nz_local) + temperature(2:n + 1, 1:n, 1:nz_local) + &
            temperature(1:n, 0:n - 1, 1:nz_local) + temperature(1:n, 2:n + 1, 1:nz_local) + &
            temperature(1:n, 1:n, 0:nz_local - 1) + temperature(1:n, 1:n, 2:nz_local + 1) - &
            6.0d0 * temperature(1:n, 1:n, 1:nz_local))
        temperature(1:n, 1:n, 1:nz_local) = next(1:n, 1:n, 1:nz_local)
        call apply_sources(temperature)
        ! After the update, so that the ghosts handed over below hold the neighbours' values
        ! of this step, and the next step's stencil reads them.
        call exchange_halos(temperature)

        ! The origin is this slab's first interior sample in the global grid.
        status = INSITU_OK
        if (insitu_selects(instrument, step)) &
            status = insitu_add_block(instrument, "temperature", temperature, &
                                      origin=[0.0d0, 0.0d0, z_first * spacing], &
                                      spacing=[spacing, spacing, spacing], &
                                      ghosts_low=[ghosts, ghosts, ghosts], &
                                      ghosts_high=[ghosts, ghosts, ghosts])
        ! Collective: every rank calls it every step, even when its own hand-over failed.
        status = merged(status, insitu_execute(instrument, step, step * dt))
        if (status < 0) then
            ! Report and go on: the simulation is worth more than its pictures.
            write (error_unit, '(a, i0, a, i0, 4a)') "heat_fortran_mpi: rank ", rank, &
                ": step ", step, ": ", insitu_status_name(status), ": ", insitu_last_error()
            failures = failures + 1
        else if (status /= INSITU_NOT_SELECTED .and. rank == 0) then
            write (*, '(a, i0, 2a)') "step ", step, ": ", insitu_status_name(status)
            if (status == INSITU_OK) stored = stored + 1
        end if
    end do

    status = insitu_finalize(instrument)
    if (status /= INSITU_OK) then
        write (error_unit, '(a, i0, 4a)') "heat_fortran_mpi: rank ", rank, ": finalize: ", &
            insitu_status_name(status), ": ", insitu_last_error()
        failures = failures + 1
    end if
    call insitu_destroy(instrument)  ! before MPI_Finalize: it frees libinsitu's communicator
    deallocate (temperature, next, config_path)
    call MPI_Allreduce(failures, any_failures, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD, ierror)
    if (rank == 0) write (*, '(a, i0, a, i0, a, i0, 3a, i0, a)') "heat_fortran_mpi: ", ranks, &
        " ranks, ", steps, " steps, ", stored, " stored in ", trim(archive), ", ", &
        any_failures, " failures (most on one rank)"
    if (any_failures /= 0) call finish(1)
    call finish(0)

contains

    !> The first failure of a step: the hand-over's if it failed, else execute's status.
    integer(c_int) function merged(handed_over, executed)
        integer(c_int), intent(in) :: handed_over, executed
        merged = executed
        if (handed_over < 0) merged = handed_over
    end function merged

    !> Holds the hot spots at temperature 1 on this rank's planes.
    subroutine apply_sources(t)
        real(c_double), intent(inout) :: t(0:, 0:, 0:)
        integer :: i, j, k, s
        do s = 1, size(spots, 2)
            do k = 0, nz_local - 1
                do j = 0, n - 1
                    do i = 0, n - 1
                        if ((i - spots(1, s))**2 + (j - spots(2, s))**2 + &
                            (z_first + k - spots(3, s))**2 <= spots(4, s)**2) &
                            t(i + ghosts, j + ghosts, k + ghosts) = 1.0d0
                    end do
                end do
            end do
        end do
    end subroutine apply_sources

    !> The halo exchange: the top interior plane up into the upper neighbour's low ghost plane,
    !> the bottom one down into the lower neighbour's high ghost plane. Whole x-y planes are
    !> contiguous in Fortran's column-major order, so they go without packing.
    subroutine exchange_halos(t)
        real(c_double), intent(inout) :: t(0:, 0:, 0:)
        integer :: plane, exchange_error
        plane = (n + 2) * (n + 2)
        call MPI_Sendrecv(t(:, :, nz_local), plane, MPI_DOUBLE_PRECISION, above, 0, &
                          t(:, :, 0), plane, MPI_DOUBLE_PRECISION, below, 0, &
                          MPI_COMM_WORLD, MPI_STATUS_IGNORE, exchange_error)
        call MPI_Sendrecv(t(:, :, 1), plane, MPI_DOUBLE_PRECISION, below, 1, &
                          t(:, :, nz_local + 1), plane, MPI_DOUBLE_PRECISION, above, 1, &
                          MPI_COMM_WORLD, MPI_STATUS_IGNORE, exchange_error)
    end subroutine exchange_halos

    !> Ends the run on every rank with `exit_status` (MPI_Finalize first, as every rank must).
    subroutine finish(exit_status)
        integer, intent(in) :: exit_status
        integer :: finalize_error
        call MPI_Finalize(finalize_error)
        if (exit_status == 0) stop
        if (exit_status == 1) stop 1, quiet=.true.
        stop 2, quiet=.true.
    end subroutine finish

    !> heat_fortran's configuration: two 32x32 views, a transfer function over [0, 1] with
    !> opacity per 0.1 world units, every 10th step, into `archive_path`.
    subroutine write_config(path, archive_path)
        character(len=*), intent(in) :: path, archive_path
        integer :: unit
        open (newunit=unit, file=path, status="replace", action="write")
        write (unit, '(a)') '{"fields": ["temperature"],'
        write (unit, '(a)') ' "views": [{"azimuth": 30, "elevation": 20, "size": [32, 32]},'
        write (unit, '(a)') '           {"azimuth": 120, "elevation": -10, "camera": "perspective",'
        write (unit, '(a)') '            "fov": 30, "size": [32, 32]}],'
        write (unit, '(a)') ' "transfer_function": {"points": [[0.0, 0, 0, 1, 0],'
        write (unit, '(a)') '     [0.3, 0, 1, 0, 0.2], [1.0, 1, 0, 0, 0.8]], "unit_length": 0.1},'
        write (unit, '(a)') ' "layers": "auto", "intervals": {"count": 8, "mode": "uniform"},'
        write (unit, '(3a)') ' "every": 10, "archive": "', json_escaped(archive_path), '",'
        write (unit, '(a)') ' "writer": {"queue": 2, "when_full": "block"}}'
        close (unit)
    end subroutine write_config

    !> `text` with JSON's string escapes for '"' and '\'.
    function json_escaped(text) result(escaped)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: escaped
        integer :: i
        escaped = ""
        do i = 1, len(text)
            if (text(i:i) == '"' .or. text(i:i) == '\') escaped = escaped//'\'
            escaped = escaped//text(i:i)
        end do
    end function json_escaped

end program heat_fortran_mpi
