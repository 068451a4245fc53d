!> tiles_fortran_mpi: a CloverLeaf-like Fortran+MPI mini-app coupled as the README's "Coupling an
!> MPI code" says (issue 43 item 7), run by tests/mpi at 1 to 4 ranks.
!>
!>   mpiexec -n RANKS tiles_fortran_mpi ARCHIVE [STEPS] [--stale-halos]
!>
!> A cell-centred density diffuses from three sources held at 1 through a box of 31 x 25 x 20
!> cells (x_min = -0.5, cells of 0.05) with cold walls. The box is cut into tiles in x and y
!> (MPI_Dims_create: 2 ranks 2 x 1, 3 ranks 3 x 1, 4 ranks 2 x 2), uneven where the cells do not
!> divide (31 = 16 + 15 = 11 + 10 + 10, 25 = 13 + 12). Each rank holds its tile with two halo
!> cells on every side, density(-1:nx+2, -1:ny+2, -1:nz+2), as CloverLeaf does, because the
!> update is a fourth-order stencil that reads two cells either way. The halos are exchanged
!> after the update (x first, then y over the whole x range, which fills the corners), before
!> the hand-over: the halo rule. The field is the 1-rank run's bit for bit at any rank count.
!>
!> --stale-halos exchanges before the update, where the stencil reads them, instead: the
!> simulation is the same, but the tile handed over keeps its neighbours' values of the step
!> before, which the halo check reports at the first step stored.
!>
!> Each rank hands its tile over with insitu_add_block(..., centering=INSITU_CELL), origin the
!> low corner of its first interior cell; rank 0 writes the configuration (ARCHIVE.json: every
!> 10th step, two views) and the archive. Exits 0 when every call succeeded on every rank, 1
!> when any failed (the run goes on to the end), 2 for bad arguments.
program tiles_fortran_mpi
    use, intrinsic :: iso_c_binding, only: c_double, c_int
    use, intrinsic :: iso_fortran_env, only: error_unit
    use mpi
    use insitu
    use insitu_mpi
    implicit none

    integer, parameter :: cells(3) = [31, 25, 20]  ! the whole box, in cells
    integer, parameter :: halo = 2                 ! halo cells on every side
    real(c_double), parameter :: h = 0.05d0        ! cell size along every axis
    real(c_double), parameter :: box_min(3) = [-0.5d0, 0.0d0, 0.0d0]
    ! Sources: centre (global cell coordinates, from 0) and radius in cells.
    real(c_double), parameter :: sources(4, 3) = reshape([8.0d0, 7.0d0, 6.0d0, 3.0d0, &
                                                          21.0d0, 15.0d0, 11.0d0, 4.0d0, &
                                                          14.0d0, 19.0d0, 14.0d0, 2.5d0], [4, 3])
    ! alpha dt / h^2; the fourth-order stencil is stable below 1/8 in 3D.
    real(c_double), parameter :: diffusion_number = 0.08d0

    real(c_double), allocatable :: density(:, :, :), next(:, :, :)
    type(insitu_instrument) :: instrument
    character(len=4096) :: archive, argument
    character(len=:), allocatable :: config_path
    integer(c_int) :: status, executed
    integer :: rank, ranks, ierror, io_status, argument_count, steps, step, failures, any_failures
    integer :: dims(2), tile(2), first(2), nx, ny, nz, left, right, down, up
    logical :: stale_halos

    call MPI_Init(ierror)
    call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierror)
    call MPI_Comm_size(MPI_COMM_WORLD, ranks, ierror)

    argument_count = command_argument_count()
    stale_halos = .false.
    if (argument_count >= 2) then
        call get_command_argument(argument_count, argument)
        if (argument == "--stale-halos") then
            stale_halos = .true.
            argument_count = argument_count - 1
        end if
    end if
    steps = 20
    io_status = 0
    if (argument_count == 2) then
        call get_command_argument(2, argument)
        read (argument, *, iostat=io_status) steps
    end if
    if (argument_count < 1 .or. argument_count > 2 .or. io_status /= 0 .or. steps < 1 .or. &
        ranks > 9) then
        if (rank == 0) write (error_unit, '(a)') &
            "usage: tiles_fortran_mpi ARCHIVE [STEPS] [--stale-halos] (STEPS > 0, at most 9 ranks)"
        call finish(2)
    end if
    call get_command_argument(1, archive)

    ! Tiles in x and y, rank = tile_x + dims(1) * tile_y; the first cells mod dims tiles get one
    ! more cell. Neighbours beyond the walls are MPI_PROC_NULL: their halos stay 0.
    dims = 0
    call MPI_Dims_create(ranks, 2, dims, ierror)
    tile = [mod(rank, dims(1)), rank / dims(1)]
    call split(cells(1), dims(1), tile(1), nx, first(1))
    call split(cells(2), dims(2), tile(2), ny, first(2))
    nz = cells(3)
    left = neighbour(tile(1) - 1, tile(2))
    right = neighbour(tile(1) + 1, tile(2))
    down = neighbour(tile(1), tile(2) - 1)
    up = neighbour(tile(1), tile(2) + 1)

    config_path = trim(archive)//".json"
    if (rank == 0) call write_config(config_path, trim(archive))
    call MPI_Barrier(MPI_COMM_WORLD, ierror)  ! the file is written before any rank reads it
    status = insitu_create_mpi(config_path, MPI_COMM_WORLD, instrument)
    if (status /= INSITU_OK) then
        if (rank == 0) write (error_unit, '(4a)') "tiles_fortran_mpi: ", &
            insitu_status_name(status), ": ", insitu_last_error()
        call finish(1)
    end if

    allocate (density(-1:nx + 2, -1:ny + 2, -1:nz + 2), next(-1:nx + 2, -1:ny + 2, -1:nz + 2))
    density = 0.0d0
    next = 0.0d0
    call hold_sources(density)
    call update_halo(density)

    failures = 0
    do step = 1, steps
        if (stale_halos) call update_halo(density)
        call advance(density, next)
        density(1:nx, 1:ny, 1:nz) = next(1:nx, 1:ny, 1:nz)
        call hold_sources(density)
        if (.not. stale_halos) call update_halo(density)  ! the halo rule

        status = INSITU_OK
        if (insitu_selects(instrument, step)) &
            status = insitu_add_block(instrument, "density", density, &
                                      origin=[box_min(1:2) + (first - 1) * h, box_min(3)], &
                                      spacing=[h, h, h], ghosts_low=[halo, halo, halo], &
                                      ghosts_high=[halo, halo, halo], centering=INSITU_CELL)
        ! Collective: every rank calls it every step, even when its own hand-over failed.
        executed = insitu_execute(instrument, step, step * diffusion_number * h**2)
        if (status == INSITU_OK) status = executed
        if (status < 0) then
            write (error_unit, '(a, i0, a, i0, 4a)') "tiles_fortran_mpi: rank ", rank, &
                ": step ", step, ": ", insitu_status_name(status), ": ", insitu_last_error()
            failures = failures + 1
        else if (status == INSITU_OK .and. rank == 0) then
            write (*, '(a, i0, a)') "step ", step, ": stored"
        end if
    end do

    status = insitu_finalize(instrument)
    if (status /= INSITU_OK) then
        write (error_unit, '(a, i0, 4a)') "tiles_fortran_mpi: rank ", rank, ": finalize: ", &
            insitu_status_name(status), ": ", insitu_last_error()
        failures = failures + 1
    end if
    call insitu_destroy(instrument)  ! before MPI_Finalize: it frees libinsitu's communicator
    call MPI_Allreduce(failures, any_failures, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD, ierror)
    if (rank == 0) write (*, '(a, i0, a, i0, a, i0, a, i0, a)') "tiles_fortran_mpi: ", ranks, &
        " ranks (", dims(1), " x ", dims(2), " tiles), ", any_failures, " failures"
    if (any_failures /= 0) call finish(1)
    call finish(0)

contains

    !> This tile's share of `total` cells cut in `parts`: `count` cells from global cell `from`
    !> (1-based); the first mod(total, parts) tiles get one more.
    subroutine split(total, parts, index, count, from)
        integer, intent(in) :: total, parts, index
        integer, intent(out) :: count, from
        count = total / parts
        from = index * count + min(index, mod(total, parts)) + 1
        if (index < mod(total, parts)) count = count + 1
    end subroutine split

    !> The rank of tile (tx, ty), MPI_PROC_NULL outside the box.
    integer function neighbour(tx, ty)
        integer, intent(in) :: tx, ty
        neighbour = MPI_PROC_NULL
        if (tx >= 0 .and. tx < dims(1) .and. ty >= 0 .and. ty < dims(2)) &
            neighbour = tx + dims(1) * ty
    end function neighbour

    !> One explicit Euler step of the fourth-order Laplacian on the interior; halos are read only.
    subroutine advance(t, t_next)
        real(c_double), intent(in) :: t(-1:, -1:, -1:)
        real(c_double), intent(inout) :: t_next(-1:, -1:, -1:)
        integer :: i, j, k
        do k = 1, nz
            do j = 1, ny
                do i = 1, nx
                    t_next(i, j, k) = t(i, j, k) + diffusion_number / 12.0d0 * ( &
                        -t(i - 2, j, k) + 16.0d0 * t(i - 1, j, k) + 16.0d0 * t(i + 1, j, k) - &
                        t(i + 2, j, k) - t(i, j - 2, k) + 16.0d0 * t(i, j - 1, k) + &
                        16.0d0 * t(i, j + 1, k) - t(i, j + 2, k) - t(i, j, k - 2) + &
                        16.0d0 * t(i, j, k - 1) + 16.0d0 * t(i, j, k + 1) - t(i, j, k + 2) - &
                        90.0d0 * t(i, j, k))
                end do
            end do
        end do
    end subroutine advance

    !> Holds the sources at density 1 on this tile's cells.
    subroutine hold_sources(t)
        real(c_double), intent(inout) :: t(-1:, -1:, -1:)
        integer :: i, j, k, s
        do s = 1, size(sources, 2)
            do k = 1, nz
                do j = 1, ny
                    do i = 1, nx
                        if ((first(1) + i - 2 - sources(1, s))**2 + &
                            (first(2) + j - 2 - sources(2, s))**2 + &
                            (k - 1 - sources(3, s))**2 <= sources(4, s)**2) t(i, j, k) = 1.0d0
                    end do
                end do
            end do
        end do
    end subroutine hold_sources

    !> The halo exchange, packed through buffers: x first over the tile's y cells, then y over
    !> the whole x range, halos included, so that the corners get the diagonal neighbours' cells.
    subroutine update_halo(t)
        real(c_double), intent(inout) :: t(-1:, -1:, -1:)
        real(c_double), allocatable :: send(:, :, :), received(:, :, :)
        allocate (send(halo, ny, nz + 2 * halo), received(halo, ny, nz + 2 * halo))
        send = t(nx - 1:nx, 1:ny, :)
        call swap(send, received, right, left, 0)
        if (left /= MPI_PROC_NULL) t(-1:0, 1:ny, :) = received
        send = t(1:2, 1:ny, :)
        call swap(send, received, left, right, 1)
        if (right /= MPI_PROC_NULL) t(nx + 1:nx + 2, 1:ny, :) = received
        deallocate (send, received)
        allocate (send(nx + 2 * halo, halo, nz + 2 * halo), &
                  received(nx + 2 * halo, halo, nz + 2 * halo))
        send = t(:, ny - 1:ny, :)
        call swap(send, received, up, down, 2)
        if (down /= MPI_PROC_NULL) t(:, -1:0, :) = received
        send = t(:, 1:2, :)
        call swap(send, received, down, up, 3)
        if (up /= MPI_PROC_NULL) t(:, ny + 1:ny + 2, :) = received
    end subroutine update_halo

    !> Sends `send` to rank `to` while receiving `received` from rank `from`.
    subroutine swap(send, received, to, from, tag)
        real(c_double), intent(in) :: send(:, :, :)
        real(c_double), intent(inout) :: received(:, :, :)
        integer, intent(in) :: to, from, tag
        integer :: swap_error
        call MPI_Sendrecv(send, size(send), MPI_DOUBLE_PRECISION, to, tag, received, &
                          size(received), MPI_DOUBLE_PRECISION, from, tag, MPI_COMM_WORLD, &
                          MPI_STATUS_IGNORE, swap_error)
    end subroutine swap

    !> Ends the run on every rank with `exit_status` (MPI_Finalize first, as every rank must).
    subroutine finish(exit_status)
        integer, intent(in) :: exit_status
        integer :: finalize_error
        call MPI_Finalize(finalize_error)
        if (exit_status == 0) stop
        if (exit_status == 1) stop 1, quiet=.true.
        stop 2, quiet=.true.
    end subroutine finish

    !> Two 32 x 32 views, a transfer function over [0, 1], every 10th step, into `archive_path`.
    subroutine write_config(path, archive_path)
        character(len=*), intent(in) :: path, archive_path
        integer :: unit
        open (newunit=unit, file=path, status="replace", action="write")
        write (unit, '(a)') '{"fields": ["density"],'
        write (unit, '(a)') ' "views": [{"azimuth": 30, "elevation": 20, "size": [32, 32]},'
        write (unit, '(a)') '           {"azimuth": 200, "elevation": 50, "camera": "perspective",'
        write (unit, '(a)') '            "fov": 35, "size": [32, 32]}],'
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

end program tiles_fortran_mpi
